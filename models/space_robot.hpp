// The robot of the paper's title: a free-floating satellite carrying a 7-DOF arm with the
// dexterous hand at its flange, in zero gravity (docs/space_robot.md).
//   {"model": "space_robot", "params": {"satellite_mass": 200, "hand": {"thumb": true}}}
// The satellite is a box on a free joint; the arm has the kinematics and link inertias of the
// KUKA LBR iiwa description in the rbd-benchmarks set; the hand is the `dexterous_hand` plugin
// (without its own wrist unless "hand": {"wrist": true}) mounted 45 mm out along link 7's axis.
#pragma once
#include "io/params.hpp"

namespace femdyn {

Json space_robot(const Params& params);

}  // namespace femdyn
