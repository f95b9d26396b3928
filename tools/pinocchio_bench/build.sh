#!/usr/bin/env bash
# Builds pin_bench (pin_bench.cpp) against a Pinocchio 3 source tree, outside femdyn's build:
# Pinocchio is not a Debian 12 package, so neither CI nor tools/setup.sh builds it.
#   PINOCCHIO_SRC=/path/to/pinocchio tools/pinocchio_bench/build.sh [OUT_DIR]
# PINOCCHIO_SRC: a checkout of github.com/stack-of-tasks/pinocchio (measured: tag v3.7.0) with
# its cmake/ submodule. OUT_DIR (default build-pinocchio) receives pin_bench. Flags as femdyn's
# Release build: -O3 -DNDEBUG and no -march (set EXTRA_FLAGS=-march=native for a native build).
# Needs, beyond tools/setup.sh --all's packages:
#   apt-get install liburdfdom-dev libboost-filesystem-dev libboost-serialization-dev \
#                   libboost-system-dev
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
src=${PINOCCHIO_SRC:?set PINOCCHIO_SRC to a Pinocchio 3 source tree (with its cmake/ submodule)}
out=$(mkdir -p "${1:-build-pinocchio}" && cd "${1:-build-pinocchio}" && pwd)
# Configure only: generates pinocchio/config.hpp and the other headers Pinocchio's CMake writes.
cmake -S "$src" -B "$out/config" -DCMAKE_BUILD_TYPE=Release -DBUILD_PYTHON_INTERFACE=OFF \
  -DBUILD_TESTING=OFF -DBUILD_WITH_URDF_SUPPORT=ON -DBUILD_BENCHMARK=OFF -DBUILD_UTILS=OFF \
  -DBUILD_DOCUMENTATION=OFF -DINSTALL_DOCUMENTATION=OFF -DENABLE_TEMPLATE_INSTANTIATION=OFF \
  >"$out/config.log"
flags="-O3 -DNDEBUG -std=c++17 ${EXTRA_FLAGS:-}"
defs="-DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DPINOCCHIO_WITH_URDFDOM"
inc="-I$out/config/include -I$src/include -isystem /usr/include/eigen3"
for part in model utils; do  # the URDF parser's two sources, compiled here instead of a library
  g++ $flags $defs -DPINOCCHIO_URDFDOM_TYPEDEF_SHARED_PTR -DPINOCCHIO_URDFDOM_USE_STD_SHARED_PTR \
    $inc -c "$src/src/parsers/urdf/$part.cpp" -o "$out/urdf_$part.o"
done
g++ $flags $defs $inc -c "$here/pin_bench.cpp" -o "$out/pin_bench.o"
g++ "$out/pin_bench.o" "$out/urdf_model.o" "$out/urdf_utils.o" \
  -lbenchmark -lpthread -lurdfdom_model -lconsole_bridge -o "$out/pin_bench"
echo "pinocchio_bench: built $out/pin_bench"
