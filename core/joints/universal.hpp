// Universal joint (Cardan, 2 DOF): the child B turns by θ₁ about the unit axis a₁ of the joint
// frame, then by θ₂ about the unit axis a₂ of the frame so turned (a₁ ⊥ a₂).
//   X_J(θ) = (Rot(a₁, θ₁) Rot(a₂, θ₂), 0).
//   S: column 1 is a₁, fixed in the parent's joint frame (given in P's axes, R_pj a₁);
//      column 2 is a₂, fixed in B (given in B's axes). The kernel's c_J takes each column's
//      frame into account (kernel.hpp): c_J = ω_P × s₁ θ̇₁ + ω_B × s₂ θ̇₂ in world axes.
#pragma once
#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct UniversalJoint : FlatJoint<2> {
  static constexpr int nq = 2, nv = 2;
  static constexpr JointAxes axes = JointAxes::Two;
  static constexpr bool angular = true, linear = false;

  static void pose(const Joint& j, const double* theta, Mat3& R, Vec3& d) {
    R = j.R_pj * axis_rotation(j.axis, theta[0]) * axis_rotation(j.axis2, theta[1]);
    d.setZero();
  }
  static Vec3 S_angular(const Joint& j, int k) { return k == 0 ? j.axis_parent : j.axis2; }
  static Vec3 S_linear(const Joint&, int) { return Vec3::Zero(); }
  static constexpr bool in_parent(int k) { return k == 0; }
  static const char* coordinate_name(int k) { return k == 0 ? "q1" : "q2"; }
  static const char* rate_name(int k) { return coordinate_name(k); }
  static void prepare(Joint& j) { j.axis_parent = j.R_pj * j.axis; }
  static constexpr double kRandomHalfRange = 3.141592653589793;  // ±π rad each
};

}  // namespace femdyn
