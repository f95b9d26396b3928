// Planar joint (3 DOF): the child B slides by (x, y) in the plane of the joint frame normal to
// the unit axis n, along e₁, e₂ (e₁ the joint frame's x axis made normal to n, or its y axis
// when x is nearly along n; e₂ = n × e₁), and turns by θ about n. Coordinates (x, y, θ).
//   X_J = (Rot(n, θ), x e₁ + y e₂)   (translation in the joint frame, then the turn).
//   S: columns x, y are e₁, e₂ fixed in the parent's joint frame (given in P's axes);
//      column θ is n (fixed in both). c_J = ω_P × (e₁ ẋ + e₂ ẏ) (kernel.hpp).
#pragma once
#include <cmath>

#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct PlanarJoint : FlatJoint<3> {
  static constexpr int nq = 3, nv = 3;
  static constexpr JointAxes axes = JointAxes::One;
  static constexpr bool angular = true, linear = true;

  static void pose(const Joint& j, const double* q, Mat3& R, Vec3& d) {
    const double s = std::sin(q[2]), c = std::cos(q[2]);
    R = j.R_pj + s * j.R_pj_K + (1 - c) * j.R_pj_K2;
    d = q[0] * j.axis2_parent + q[1] * j.axis3_parent;
  }
  static Vec3 S_angular(const Joint& j, int k) { return k == 2 ? j.axis : Vec3::Zero(); }
  static Vec3 S_linear(const Joint& j, int k) {
    return k == 0 ? j.axis2_parent : k == 1 ? j.axis3_parent : Vec3::Zero();
  }
  static constexpr bool in_parent(int k) { return k < 2; }
  static const char* coordinate_name(int k) { return k == 0 ? "x" : k == 1 ? "y" : "theta"; }
  static const char* rate_name(int k) { return coordinate_name(k); }
  static void prepare(Joint& j);
  static constexpr double kRandomHalfRange = 0.5;  // ±0.5 m along e₁, e₂; θ within ±π
};

}  // namespace femdyn
