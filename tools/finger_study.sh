#!/usr/bin/env bash
# Generates the error table of docs/finger.md: the paper's discretisation of the finger
# (models/finger_paper.json) against the exact model (models/finger.json), by `femdyn compare`.
# Usage: tools/finger_study.sh [path/to/femdyn]   (prints Markdown; paste between the markers)
set -euo pipefail
cd "$(dirname "$0")/.."
femdyn=${1:-./build/femdyn}
paper=models/finger_paper.json exact=models/finger.json

row() {  # label, then compare options
  local label=$1; shift
  "$femdyn" compare "$paper" "$exact" --json --tau 0.01,0.01,0.01,0.01 "$@" | python3 -c "
import json, sys
j = json.load(sys.stdin)
m, h, a = (j['max_rel_error'][k] for k in ('M', 'h', 'qdd'))
f = lambda x: '%.2e' % x
print('| $label | ' + ' | '.join(map(f, (m, h, a))) + ' |')"
}

echo "| state (θ1, θ2, θ3, θ4 in rad; θ̇ in rad/s; τ = 0.01 N·m on each joint) | M^s | h | q̈ |"
echo "|---|---|---|---|"
row "straight, at rest: q = 0, θ̇ = 0" --q 0,0,0,0
row "pure flexion, at rest: q = (0, 0.5, 0.6, 0.5)" --q 0,0.5,0.6,0.5
row "pure flexion, moving: q = (0, 0.5, 0.6, 0.5), θ̇ = (0, 2, 2, 2)" --q 0,0.5,0.6,0.5 --qd 0,2,2,2
row "abduction with flexion: q = (0.3, 0.5, 0.6, 0.5), θ̇ = (1, 2, 2, 2)" --q 0.3,0.5,0.6,0.5 --qd 1,2,2,2
row "fast abduction: q = (0.3, 0.5, 0.6, 0.5), θ̇ = (10, 0, 0, 0)" --q 0.3,0.5,0.6,0.5 --qd 10,0,0,0
row "high speed: q = (0.3, 0.5, 0.6, 0.5), θ̇ = (10, 10, 10, 10)" --q 0.3,0.5,0.6,0.5 --qd 10,10,10,10
row "100 seeded random states in the joint limits, θ̇ in ±2 (max)" --states 100 --seed 1
