// A seeded random mechanism, for tests, studies and benchmarks: a tree of `bodies` bodies with
// random joint axes, offsets and rpy, revolute joints (and, with "prismatic": true, one
// prismatic joint in four), each body a rigid body with a random full, physical inertia tensor.
//   {"model": "random_tree", "params": {"seed": 7, "bodies": 20, "branching": 0.5}}
// "branching" in [0, 1] is the chance a body hangs from a random earlier body rather than the
// last one (0: a serial chain). The same parameters always give the same mechanism.
#pragma once
#include "io/params.hpp"

namespace femdyn {

Json random_tree(const Params& params);

}  // namespace femdyn
