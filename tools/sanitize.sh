#!/usr/bin/env bash
# Sanitizers (docs/robustness.md#sanitizers): builds femdyn, its tests and the validation in
# ./build-asan with -DFEMDYN_SANITIZE=ON (clang++, AddressSanitizer + UndefinedBehaviorSanitizer,
# -O1 -g1 with asserts on) and runs the whole ctest suite under them. clang, as tools/fuzz.sh:
# it compiles this code in 0.6 of GCC's time under the same flags (docs/building.md). Exits non-zero on a build
# failure, a sanitizer report or a failed test. Dependencies: those of tools/setup.sh --all.
#   tools/sanitize.sh            e.g. CI, after tools/setup.sh --all
#   JOBS=4 tools/sanitize.sh     parallel build and test jobs (default: nproc)
# Skipped under sanitizers: the malloc-counting tests ([hot-path], reported as Skipped by ctest)
# and femdyn_bench with its smoke test (not built).
set -euo pipefail
cd "$(dirname "$0")/.."

build=build-asan
jobs=${JOBS:-$(nproc)}
mkdir -p "$build"
log=$build/build.log
testlog=$build/ctest.log

# Runtime options, also for the test discovery run during the build (catch_discover_tests).
# halt_on_error / -fno-sanitize-recover: the first report ends the process with an error, so
# ctest sees the test fail (a CLI run by a test exits 1 and its output names the report).
# Leaks are detected (LeakSanitizer at exit; tools/lsan.supp for uninstrumented libraries).
# Container-overflow checks need annotated containers: GCC's libstdc++ has none unless
# _GLIBCXX_SANITIZE_VECTOR is defined, so none can misfire across Simbody or CHOLMOD.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:check_initialization_order=1:strict_init_order=1:detect_stack_use_after_return=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$PWD/tools/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"

t0=$(date +%s)
# A build directory configured with another compiler (GCC, before) is configured afresh.
if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang++' "$build/CMakeCache.txt"; then
  rm -rf "$build"
  mkdir -p "$build"
fi
generator=()
[ -f "$build/CMakeCache.txt" ] || generator=(-G Ninja -DCMAKE_CXX_COMPILER=clang++)
if ! { cmake -S . -B "$build" "${generator[@]}" -DFEMDYN_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
         "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" &&
       cmake --build "$build" -j"$jobs"; } >"$log" 2>&1; then
  tail -n 60 "$log" >&2
  echo "sanitize: build failed (last lines above; whole log: $log)" >&2
  exit 1
fi
t1=$(date +%s)
echo "sanitize: configured and built $build in $((t1 - t0)) s (log: $log)"

status=0
ctest --test-dir "$build" --output-on-failure -j"$jobs" >"$testlog" 2>&1 || status=$?
t2=$(date +%s)
if [ "$status" -ne 0 ]; then
  # Everything but the passing tests' lines: failing tests' output and sanitizer reports.
  grep -v -E '^ *Start +[0-9]+: |^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* (Passed|\*\*\*Skipped) ' \
    "$testlog" >&2 || true
  echo "sanitize: FAILED after $((t2 - t1)) s of tests (whole log: $testlog)" >&2
  exit 1
fi
sed -n -E '/tests passed/p; /did not run:/,$p' "$testlog" | grep -v -E '^(Total Test time|$)'
echo "sanitize: all tests passed under ASan + UBSan in $((t2 - t1)) s (log: $testlog)"
