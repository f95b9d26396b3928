#include "core/joints/revolute.hpp"

namespace femdyn {

void RevoluteJoint::prepare(Joint& j) {
  const Mat3 K = skew(j.axis);
  j.R_pj_K = j.R_pj * K;
  j.R_pj_K2 = j.R_pj_K * K;
}

}  // namespace femdyn
