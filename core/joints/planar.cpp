#include "core/joints/planar.hpp"

#include "core/joints/revolute.hpp"

namespace femdyn {

void PlanarJoint::prepare(Joint& j) {
  RevoluteJoint::prepare(j);
  Vec3 e1 = std::abs(j.axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  e1 = (e1 - e1.dot(j.axis) * j.axis).normalized();
  j.axis2 = e1;
  j.axis2_parent = j.R_pj * e1;
  j.axis3_parent = j.R_pj * j.axis.cross(e1);
}

}  // namespace femdyn
