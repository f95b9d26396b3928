#include "core/joints/helical.hpp"

#include "core/joints/revolute.hpp"

namespace femdyn {

void HelicalJoint::prepare(Joint& j) {
  RevoluteJoint::prepare(j);
  j.axis_parent = j.R_pj * j.axis;
}

}  // namespace femdyn
