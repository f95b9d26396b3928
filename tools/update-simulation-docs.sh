#!/usr/bin/env bash
# Regenerates the study sections of docs/simulation.md: `femdyn study` on the finger (both
# engines interpolating at the samples, then both landing on them) and on the hand writes
# docs/simulation/<name>/ (study.csv, study.md, study.gp, study.png), and each study.md replaces
# the text between its markers in docs/simulation.md. Timings are this machine's, medians of
# timed runs after a warm-up, with the load average at the start and end of each study in its
# study.md and study.csv: run on an idle machine if you can, with the Release build
# (tools/setup.sh --all).
set -euo pipefail
cd "$(dirname "$0")/.."
femdyn=./build/femdyn
[ -x "$femdyn" ] || { echo "build femdyn first (tools/setup.sh --all)" >&2; exit 1; }

study() {  # name, model, extra options
  local name=$1 model=$2
  shift 2
  "$femdyn" study "$model" --out "docs/simulation/$name" --force "$@"
}
study finger models/finger.json
study finger-land models/finger.json --land-on-samples
study hand models/hand.json --t-end 0.25  # chaotic beyond ~0.3 s (docs/validation.md)

# Splice: between "<!-- study NAME -->" and "<!-- /study NAME -->", the study's summary with
# its title one level down and the plot's path from docs/.
python3 - <<'PY'
import re
path = "docs/simulation.md"
doc = open(path, encoding="utf-8").read()
for name in ("finger", "finger-land", "hand"):
    md = open(f"docs/simulation/{name}/study.md", encoding="utf-8").read()
    md = md.replace("](study.png)", f"](simulation/{name}/study.png)")
    md = re.sub(r"^# ", "### ", md, count=1)
    cut = md.find("Every run")  # the full table stays in the study's own study.md
    if cut >= 0:
        md = md[:cut] + f"Every run, with its evaluations, steps and energy: [simulation/{name}/study.md](simulation/{name}/study.md), [study.csv](simulation/{name}/study.csv).\n"
    begin, end = f"<!-- study {name} -->", f"<!-- /study {name} -->"
    a, b = doc.index(begin) + len(begin), doc.index(end)
    doc = doc[:a] + "\n" + md.rstrip() + "\n" + doc[b:]
open(path, "w", encoding="utf-8").write(doc)
PY
echo "docs/simulation.md updated" >&2
