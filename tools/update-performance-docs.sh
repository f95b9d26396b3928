#!/usr/bin/env bash
# Regenerates docs/performance.md, docs/performance/{times.csv,chains.dat,scaling.gp,scaling.png,
# load.csv} from one femdyn_bench run (about 7 minutes). Timings are this machine's: run on an idle
# machine with the Release build (tools/setup.sh --all).
set -euo pipefail
cd "$(dirname "$0")/.."
bench=./build/femdyn_bench
[ -x "$bench" ] || { echo "build femdyn_bench first (tools/setup.sh --all)" >&2; exit 1; }
json=$(mktemp --suffix=.json)
trap 'rm -f "$json"' EXIT
# --load: only the section "Loading and compiling against n" (the load/ benchmarks, about two
# minutes); the rest of docs/performance.md is kept.
filter=() section=()
if [ "${1:-}" = --load ]; then filter=(--benchmark_filter='^load/') section=(--load); fi
"$bench" --benchmark_min_time=0.1 --benchmark_repetitions=3 "${filter[@]}" \
  --benchmark_report_aggregates_only=true --benchmark_out="$json" --benchmark_out_format=json \
  >/dev/null
python3 tools/performance_report.py "$json" docs/performance docs/performance.md "${section[@]}"
