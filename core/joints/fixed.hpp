// Fixed joint: the child B is welded to its parent at the joint frame. X_J = identity, no
// coordinate, S has no column.
#pragma once
#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct FixedJoint : FlatJoint<0> {
  static constexpr int nq = 0, nv = 0;
  static constexpr JointAxes axes = JointAxes::None;
  static constexpr bool angular = false, linear = false;

  static void pose(const Joint& j, const double*, Mat3& R, Vec3& d) {
    R = j.R_pj;
    d.setZero();
  }
  static Vec3 S_angular(const Joint&, int) { return Vec3::Zero(); }
  static Vec3 S_linear(const Joint&, int) { return Vec3::Zero(); }
  static constexpr bool in_parent(int) { return false; }  // every column fixed in B
  static void prepare(Joint&) {}
  static constexpr double kRandomHalfRange = 0;
};

}  // namespace femdyn
