#include "core/joints/prismatic.hpp"

namespace femdyn {

void PrismaticJoint::prepare(Joint& j) { j.axis_parent = j.R_pj * j.axis; }

}  // namespace femdyn
