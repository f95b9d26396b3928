// Revolute joint: the child B turns by θ about the unit axis a of the joint frame.
//   X_J(θ) = (Rot(a, θ), 0),   S = (a, 0) in B's axes about B's origin (which lies on the axis),
//   c_J = 0 (S is constant in B).
// R_pj Rot(a, θ) by Rodrigues with the products precomputed at compile:
//   R_pj (1 + sin θ [a]× + (1 − cos θ) [a]×²) = R_pj + sin θ R_pj[a]× + (1 − cos θ) R_pj[a]×².
#pragma once
#include <cmath>

#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct RevoluteJoint : FlatJoint<1> {
  static constexpr int nq = 1, nv = 1;
  static constexpr JointAxes axes = JointAxes::One;
  static constexpr bool angular = true, linear = false;  // the non-zero halves of S

  // B's orientation in the parent's frame, R_pj R_J(θ), and its origin's displacement from the
  // joint frame's, d = R_pj p_J(θ) (0: B's origin is the joint's).
  static void pose(const Joint& j, const double* theta, Mat3& R, Vec3& d) {
    const double s = std::sin(theta[0]), c = std::cos(theta[0]);
    R = j.R_pj + s * j.R_pj_K + (1 - c) * j.R_pj_K2;
    d.setZero();
  }
  static Vec3 S_angular(const Joint& j, int) { return j.axis; }
  static Vec3 S_linear(const Joint&, int) { return Vec3::Zero(); }
  // Compile: the constants pose() uses.
  static constexpr bool in_parent(int) { return false; }  // every column fixed in B
  static void prepare(Joint& j);
  // Half the width of the range a random configuration is drawn from (validation, sampling).
  static constexpr double kRandomHalfRange = 3.141592653589793;  // ±π rad
};

}  // namespace femdyn
