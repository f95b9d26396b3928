// Spherical joint (ball, 3 DOF): the child B turns freely about the joint frame's origin.
//   q = (w, x, y, z), a unit quaternion (nq = 4); v = ω, B's angular velocity relative to the
//   parent in B's axes (nv = 3), so q̇ = ½ q ⊗ (0, ω).
//   X_J(q) = (R(q), 0),   S = (1, 0) in B's axes (constant), c_J = 0.
// Its configuration is not a vector space: q ⊕ ξ = q ⊗ exp(ξ), q₁ ⊖ q₀ = log(q₀⁻¹ q₁), and in
// the chart around q_c, ξ̇ = J_r(ξ)⁻¹ ω (core/joints/rotation.hpp).
#pragma once
#include <random>

#include "core/joints/parameters.hpp"
#include "core/joints/rotation.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct SphericalJoint {
  static constexpr int nq = 4, nv = 3;
  static constexpr JointAxes axes = JointAxes::None;
  static constexpr bool angular = true, linear = false, flat = false;

  static void pose(const Joint& j, const double* q, Mat3& R, Vec3& d) {
    R = j.R_pj * quaternion_rotation(q);
    d.setZero();
  }
  static Vec3 S_angular(const Joint&, int k) { return Vec3::Unit(k); }
  static Vec3 S_linear(const Joint&, int) { return Vec3::Zero(); }
  static constexpr bool in_parent(int) { return false; }
  static const char* coordinate_name(int k) {
    static constexpr const char* kNames[] = {"qw", "qx", "qy", "qz"};
    return kNames[k];
  }
  static const char* rate_name(int k) {
    static constexpr const char* kNames[] = {"wx", "wy", "wz"};
    return kNames[k];
  }
  static void prepare(Joint&) {}

  static void integrate(const Joint&, const double* q, const double* xi, double* out) {
    quaternion_integrate(q, xi, out);
  }
  static void difference(const Joint&, const double* q0, const double* q1, double* xi) {
    const Vec3 d = quaternion_difference(q0, q1);
    for (int k = 0; k < 3; ++k) xi[k] = d[k];
  }
  static void chart_rate(const Joint&, const double*, const double* xi, const double* v,
                         double* xi_dot) {
    const Vec3 r = inverse_right_jacobian_times(Vec3(xi[0], xi[1], xi[2]), Vec3(v[0], v[1], v[2]));
    for (int k = 0; k < 3; ++k) xi_dot[k] = r[k];
  }
  // ∂ξ̇/∂ξ at ξ = 0: J_r(ξ)⁻¹ ω = ω + ½ ξ × ω + O(ξ²), so −½ [ω]× (row-major into A).
  static void chart_rate_jacobian(const Joint&, const double* v, double* A) {
    add_skew(-0.5, v, A, 3);
  }
  static void neutral(double* q) { q[0] = 1, q[1] = q[2] = q[3] = 0; }
  static constexpr double kRandomHalfRange = 3.141592653589793;  // uniform over all rotations
};

}  // namespace femdyn
