// Helical joint (a screw): the child B turns by θ about the unit axis a of the joint frame and
// advances p θ along it (p the pitch, m/rad).
//   X_J(θ) = (Rot(a, θ), p θ a),   S = (a, p a) in B's axes (the axis is shared), c_J = 0.
#pragma once
#include <cmath>

#include "core/joints/flat.hpp"
#include "core/joints/parameters.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct HelicalJoint : FlatJoint<1> {
  static constexpr int nq = 1, nv = 1;
  static constexpr JointAxes axes = JointAxes::One;
  static constexpr JointScalar scalars[] = {
      {"pitch", &Joint::pitch, "the advance along the axis per radian, m/rad", 0.05}};
  static constexpr bool angular = true, linear = true;

  // R_pj Rot(a, θ) by Rodrigues (as the revolute joint), d = p θ R_pj a.
  static void pose(const Joint& j, const double* theta, Mat3& R, Vec3& d) {
    const double s = std::sin(theta[0]), c = std::cos(theta[0]);
    R = j.R_pj + s * j.R_pj_K + (1 - c) * j.R_pj_K2;
    d = (j.pitch * theta[0]) * j.axis_parent;
  }
  static Vec3 S_angular(const Joint& j, int) { return j.axis; }
  static Vec3 S_linear(const Joint& j, int) { return j.pitch * j.axis; }
  static constexpr bool in_parent(int) { return false; }
  static void prepare(Joint& j);
  static constexpr double kRandomHalfRange = 3.141592653589793;  // ±π rad
};

}  // namespace femdyn
