#!/usr/bin/env bash
# Regenerates the results of docs/stability.md: `femdyn stress` (the full suite, about two
# minutes on 2 cores) writes docs/stability/stress.md and stress.csv, and stress.md replaces
# the text between "<!-- stress -->" and "<!-- /stress -->" in docs/stability.md.
set -euo pipefail
cd "$(dirname "$0")/.."
femdyn=./build/femdyn
[ -x "$femdyn" ] || { echo "build femdyn first (tools/setup.sh --all)" >&2; exit 1; }
"$femdyn" stress --out docs/stability --force >/dev/null
python3 - <<'PY'
path = "docs/stability.md"
doc = open(path, encoding="utf-8").read()
table = open("docs/stability/stress.md", encoding="utf-8").read()
begin, end = "<!-- stress -->", "<!-- /stress -->"
a, b = doc.index(begin) + len(begin), doc.index(end)
doc = doc[:a] + "\n" + table.rstrip() + "\n" + doc[b:]
open(path, "w", encoding="utf-8").write(doc)
PY
echo "docs/stability.md updated" >&2
