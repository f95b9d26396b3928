#!/usr/bin/env bash
# Installs femdyn's dependencies from Debian 12's packages and builds it in Release, into ./build.
#   tools/setup.sh          the packages the command-line program needs, and the femdyn
#                           executable alone (the README's first command: a few minutes)
#   tools/setup.sh --all    every package (Simbody, MuJoCo, Catch2, pybind11, Chromium, clang, …),
#                           three.js for `femdyn view` (npm), and everything: femdyn with
#                           validate/study/stress/bench/view, the Python module, the tests and
#                           the benchmarks (the README's second command, and CI)
# Idempotent: re-running only installs what is missing and rebuilds what changed. Run from
# anywhere. docs/building.md has the figures and the build's options.
set -euo pipefail
cd "$(dirname "$0")/.."

all=0
case "${1:-}" in
  "") ;;
  --all) all=1 ;;
  *) echo "usage: tools/setup.sh [--all]   (unknown option '$1')" >&2; exit 2 ;;
esac

# The command-line program: a compiler, CMake, Ninja and the libraries femdyn links.
packages=(cmake g++ make ninja-build libeigen3-dev libsuitesparse-dev nlohmann-json3-dev
          libtinyxml2-dev libsundials-dev libqhull-dev)
if [ "$all" = 1 ]; then
  packages+=(catch2 libsimbody-dev libmujoco-dev libbenchmark-dev gnuplot-nox
             fonts-dejavu-core clang libclang-rt-14-dev clang-format universal-ctags
             pybind11-dev python3-dev python3-numpy python3-pytest python3-pandas
             python3-matplotlib python3-distributed python3-jsonschema python3-scipy
             chromium)
  # npm fetches three.js for femdyn view (below); Debian's package unless an npm is there
  # already (NodeSource's nodejs ships its own and conflicts with Debian's npm).
  command -v npm >/dev/null || packages+=(npm)
fi

t0=$(date +%s)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "femdyn setup: installing ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "femdyn setup: packages installed in $(($(date +%s) - t0)) s" >&2
fi

# three.js for `femdyn view` (docs/view.md): the version pinned by web/package-lock.json, from the
# npm registry, into web/node_modules; again only when the lock file changed since.
if [ "$all" = 1 ] && ! cmp -s web/package-lock.json web/node_modules/.femdyn-lock.json 2>/dev/null; then
  echo "femdyn setup: npm ci in web/ (three.js for femdyn view)" >&2
  t0=$(date +%s)
  (cd web && npm ci --no-audit --no-fund --ignore-scripts >/dev/null &&
   cp package-lock.json node_modules/.femdyn-lock.json)
  echo "femdyn setup: three.js installed in $(($(date +%s) - t0)) s" >&2
fi

# Ninja (its .ninja_log holds each unit's compile time: docs/building.md); a build directory
# configured earlier with another generator keeps it.
t0=$(date +%s)
generator=()
[ -f build/CMakeCache.txt ] || generator=(-G Ninja)
if [ "$all" = 1 ]; then
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DFEMDYN_REQUIRE_ALL=ON >/dev/null
  cmake --build build -j"$(nproc)" >/dev/null
  echo "femdyn setup: built everything in $(($(date +%s) - t0)) s: ./build/femdyn, the tests," \
       "the Python module (PYTHONPATH=build/python)" >&2
else
  cmake -S . -B build "${generator[@]}" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"$(nproc)" --target femdyn >/dev/null
  echo "femdyn setup: built ./build/femdyn in $(($(date +%s) - t0)) s (tools/setup.sh --all" \
       "builds the rest: validation, view, Python module, tests)" >&2
fi
