#!/usr/bin/env bash
# Fuzzing (docs/robustness.md#fuzzing): builds the libFuzzer targets of tests/fuzz/ in
# ./build-fuzz (clang++, -DFEMDYN_FUZZ=ON, ASan + UBSan) and runs each for SECONDS (default 60)
# on its seed corpus, as many side by side as there are cores. Exits 1 if a target found a bug
# (a crash, sanitizer report, unexpected exception, an error message with a control character,
# timeout, out-of-memory or NaN), naming the input kept in build-fuzz/artifacts/.
#   tools/fuzz.sh [SECONDS]          e.g. CI: tools/fuzz.sh 60
#   FEMDYN_FUZZ_NAN_CHECK=1 tools/fuzz.sh   NaN/Inf results on finite input count as bugs
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-60}
if ! [[ $seconds =~ ^[0-9]+$ ]] || [ "$seconds" -lt 1 ]; then
  echo "usage: tools/fuzz.sh [SECONDS]   (seconds per target, default 60)" >&2
  exit 2
fi
build="build-fuzz"
mkdir -p "$build/artifacts"
log=$build/build.log

# Build: everything instrumented, asserts on (-O1 -g without NDEBUG), only what the targets need.
t0=$(date +%s)
generator=()
[ -f "$build/CMakeCache.txt" ] || generator=(-G Ninja)
if ! { cmake -S . -B "$build" "${generator[@]}" -DCMAKE_CXX_COMPILER=clang++ -DFEMDYN_FUZZ=ON \
         -DFEMDYN_BUILD_TESTS=OFF -DFEMDYN_WITH_SIMBODY=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
         "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g" &&
       cmake --build "$build" -j"$(nproc)" --target fuzz_targets; } >"$log" 2>&1; then
  cat "$log" >&2
  echo "fuzz: build failed (log above, also in $log)" >&2
  exit 1
fi
echo "fuzz: built $build in $(($(date +%s) - t0)) s (log: $log)"

# target  max_len  dictionary  seed corpora (read only; new inputs go to build-fuzz/corpus/TARGET)
targets=(
  "json_model 8192 tests/fuzz/json_model.dict models tests/fuzz/corpus/json_model"
  "urdf 20480 tests/fuzz/urdf.dict models/urdf tests/robots"
  "vector 256 - tests/fuzz/corpus/vector"
  "csv 4096 tests/fuzz/csv.dict tests/fuzz/corpus/csv"
)
# fuzz_one NAME MAX_LEN DICT SEEDS…: one target for SECONDS; prints its summary line, and into
# $build/found-NAME the bug inputs it wrote (one per line), if any.
fuzz_one() {
  local name=$1 max_len=$2 dict=$3
  shift 3
  local corpus=$build/corpus/$name before last status runs cov new t1
  mkdir -p "$corpus"
  rm -f "$build/found-$name"
  before=$(ls "$build/artifacts" | grep "^$name-" || true)
  # The scratch corpus keeps every input that was once new; loading 10,000 of them takes longer
  # than a short run. Above 1,000 files, and twice its size after the last minimisation, it is
  # minimised first (libFuzzer -merge=1).
  last=$(cat "$corpus.minimised" 2>/dev/null || echo 500)
  if [ "$(ls "$corpus" | wc -l)" -gt $((2 * last)) ]; then
    rm -rf "$corpus.min" && mkdir "$corpus.min"
    if "$build/tests/fuzz/fuzz_$name" -merge=1 -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" \
         -artifact_prefix="$build/artifacts/$name-" "$corpus.min" "$corpus" \
         >"$build/merge-$name.log" 2>&1; then
      echo "fuzz: $name: scratch corpus minimised from $(ls "$corpus" | wc -l) to $(ls "$corpus.min" | wc -l) files"
      rm -rf "$corpus" && mv "$corpus.min" "$corpus"
      ls "$corpus" | wc -l >"$corpus.minimised"
    else
      rm -rf "$corpus.min"  # keep the corpus as it is (log: $build/merge-$name.log)
    fi
  fi
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len"
              -artifact_prefix="$build/artifacts/$name-" -print_final_stats=1)
  [ "$dict" != - ] && args+=(-dict="$dict")
  t1=$(date +%s)
  if "$build/tests/fuzz/fuzz_$name" "${args[@]}" "$corpus" "$@" "tests/fuzz/regressions/$name" \
       >"$build/fuzz-$name.log" 2>&1; then
    status=ok
  else
    status=failed
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$build/fuzz-$name.log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$build/fuzz-$name.log" | tail -1 || true)
  new=$(LC_ALL=C comm -13 <(echo "$before" | LC_ALL=C sort) \
          <(ls "$build/artifacts" | grep "^$name-" | LC_ALL=C sort) | sed "s|^|$build/artifacts/|")
  echo "fuzz: $name: $(($(date +%s) - t1)) s, ${runs:-?} inputs, ${cov:-cov: ?}, corpus $(ls "$corpus" | wc -l) files: $status"
  if [ "$status" != ok ] || [ -n "$new" ]; then
    grep -E 'BUG:|ERROR:|SUMMARY:|runtime error|Assertion|Test unit written' "$build/fuzz-$name.log" | head -20 >&2 || true
    if [ -z "$new" ]; then
      echo "$name: no artifact written, see $build/fuzz-$name.log" >"$build/found-$name"
    else
      for a in $new; do echo "$name: $a"; done >"$build/found-$name"
    fi
  fi
}

# The targets run side by side, as many at once as there are cores: each still has SECONDS of
# a core of its own.
jobs=$(nproc)
running=0
for spec in "${targets[@]}"; do
  # shellcheck disable=SC2086  # the seed corpora: a list of directories
  fuzz_one $spec &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait
found=()
for spec in "${targets[@]}"; do
  read -r name _ <<<"$spec"
  [ -f "$build/found-$name" ] && mapfile -t -O "${#found[@]}" found <"$build/found-$name"
done

if [ ${#found[@]} -gt 0 ]; then
  echo "fuzz: FAILED, bug inputs:" >&2
  printf '  %s\n' "${found[@]}" >&2
  echo "fuzz: reproduce with $build/tests/fuzz/fuzz_TARGET INPUT; once understood, copy the input" \
       "to tests/fuzz/regressions/TARGET/ (replayed by ctest)" >&2
  exit 1
fi
echo "fuzz: no bug found"
