#!/usr/bin/env bash
# Installs femdyn's build dependencies from Debian 12's packages and builds it in Release.
# Idempotent: re-running only rebuilds what changed. Run from anywhere; builds into ./build.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake g++ make libeigen3-dev libsuitesparse-dev nlohmann-json3-dev catch2
          libsimbody-dev libmujoco-dev libtinyxml2-dev libbenchmark-dev libsundials-dev gnuplot-nox
          fonts-dejavu-core clang libclang-rt-14-dev clang-format
          pybind11-dev python3-dev python3-numpy python3-pytest python3-pandas
          python3-matplotlib python3-distributed python3-jsonschema python3-scipy
          chromium)
# npm fetches three.js for femdyn view (below); Debian's package unless an npm is there already
# (NodeSource's nodejs ships its own and conflicts with Debian's npm).
command -v npm >/dev/null || packages+=(npm)

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
fi

# three.js for `femdyn view` (docs/view.md): the version pinned by web/package-lock.json, from the
# npm registry, into web/node_modules; again only when the lock file changed since.
if ! cmp -s web/package-lock.json web/node_modules/.femdyn-lock.json 2>/dev/null; then
  echo "femdyn setup: npm ci in web/ (three.js for femdyn view)" >&2
  (cd web && npm ci --no-audit --no-fund --ignore-scripts >/dev/null &&
   cp package-lock.json node_modules/.femdyn-lock.json)
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" >/dev/null
echo "femdyn setup: built ./build/femdyn and the Python module (PYTHONPATH=build/python)" >&2
