#!/usr/bin/env bash
# Pinocchio's computeABADerivatives and aba against femdyn's derivatives and forward dynamics on
# the same machine: three rounds, the two benchmarks alternating, each round's medians of five
# repetitions; prints each timing's three medians. Run from the repository root on an idle
# machine, after building femdyn (build/) and pin_bench (build.sh):
#   tools/pinocchio_bench/compare.sh [PIN_BENCH] [FEMDYN_BENCH]
set -euo pipefail
pin=${1:-build-pinocchio/pin_bench}
fem=${2:-build/femdyn_bench}
reps=(--benchmark_repetitions=5 --benchmark_report_aggregates_only=true)
for _ in 1 2 3; do
  "$pin" --robots=tests/robots "${reps[@]}" 2>/dev/null | awk '/_median/ {print $1, $2, $3}'
  "$fem" --benchmark_filter='femdyn/(forward|derivatives)/(iiwa|hyq|atlas)(_floating)?$' \
    "${reps[@]}" 2>/dev/null | awk '/_median/ {print $1, $2, $3}'
done | awk '{t[$1] = t[$1] " " $2 " " $3} END {for (k in t) print k t[k]}' | sort
