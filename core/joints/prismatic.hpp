// Prismatic joint: the child B slides by θ along the unit axis a of the joint frame.
//   X_J(θ) = (1, a θ),   S = (0, a) in B's axes (B keeps the joint frame's orientation),
//   c_J = 0.
#pragma once
#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct PrismaticJoint : FlatJoint<1> {
  static constexpr int nq = 1, nv = 1;
  static constexpr JointAxes axes = JointAxes::One;
  static constexpr bool angular = false, linear = true;

  static void pose(const Joint& j, const double* theta, Mat3& R, Vec3& d) {
    R = j.R_pj;
    d = j.axis_parent * theta[0];
  }
  static Vec3 S_angular(const Joint&, int) { return Vec3::Zero(); }
  static Vec3 S_linear(const Joint& j, int) { return j.axis; }
  static constexpr bool in_parent(int) { return false; }  // every column fixed in B
  static void prepare(Joint& j);
  static constexpr double kRandomHalfRange = 0.5;  // ±0.5 m
};

}  // namespace femdyn
