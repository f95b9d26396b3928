// Free joint (6 DOF, a floating base): the child B moves freely relative to the joint frame.
//   q = (x, y, z, w, qx, qy, qz): B's origin in the joint frame, then a unit quaternion
//   (nq = 7); v = (v, ω): the velocity of B's origin and B's angular velocity, both relative
//   to the parent and in B's axes (nv = 6; Pinocchio's convention), so ṗ = R(q) v.
//   X_J(q) = (R(q), p),   S = 1 (6 × 6) in B's axes, linear columns first (constant), c_J = 0.
// q ⊕ ξ = (p + R ξ_p, q ⊗ exp(ξ_r)); in the chart around q_c, ξ̇ = (exp(ξ_r) v, J_r(ξ_r)⁻¹ ω).
#pragma once
#include "core/joints/parameters.hpp"
#include "core/joints/rotation.hpp"
#include "core/model/model.hpp"

namespace femdyn {

struct FreeJoint {
  static constexpr int nq = 7, nv = 6;
  static constexpr JointAxes axes = JointAxes::None;
  static constexpr bool angular = true, linear = true, flat = false;

  static void pose(const Joint& j, const double* q, Mat3& R, Vec3& d) {
    R = j.R_pj * quaternion_rotation(q + 3);
    d = j.R_pj * Vec3(q[0], q[1], q[2]);
  }
  static Vec3 S_angular(const Joint&, int k) {
    return k < 3 ? Vec3(Vec3::Zero()) : Vec3(Vec3::Unit(k - 3));
  }
  static Vec3 S_linear(const Joint&, int k) {
    return k < 3 ? Vec3(Vec3::Unit(k)) : Vec3(Vec3::Zero());
  }
  static constexpr bool in_parent(int) { return false; }
  static const char* coordinate_name(int k) {
    static constexpr const char* kNames[] = {"x", "y", "z", "qw", "qx", "qy", "qz"};
    return kNames[k];
  }
  static const char* rate_name(int k) {
    static constexpr const char* kNames[] = {"vx", "vy", "vz", "wx", "wy", "wz"};
    return kNames[k];
  }
  static void prepare(Joint&) {}

  static void integrate(const Joint&, const double* q, const double* xi, double* out) {
    const Vec3 p = Vec3(q[0], q[1], q[2]) + quaternion_rotation(q + 3) * Vec3(xi[0], xi[1], xi[2]);
    quaternion_integrate(q + 3, xi + 3, out + 3);
    for (int k = 0; k < 3; ++k) out[k] = p[k];
  }
  static void difference(const Joint&, const double* q0, const double* q1, double* xi) {
    const Vec3 d =
        quaternion_rotation(q0 + 3).transpose() * Vec3(q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]);
    const Vec3 r = quaternion_difference(q0 + 3, q1 + 3);
    for (int k = 0; k < 3; ++k) xi[k] = d[k], xi[3 + k] = r[k];
  }
  static void chart_rate(const Joint&, const double*, const double* xi, const double* v,
                         double* xi_dot) {
    const Vec3 r(xi[3], xi[4], xi[5]), w(v[3], v[4], v[5]);
    const double angle = r.norm();
    const Mat3 E = angle > 0 ? axis_rotation(r / angle, angle) : Mat3::Identity();
    const Vec3 p = E * Vec3(v[0], v[1], v[2]), a = inverse_right_jacobian_times(r, w);
    for (int k = 0; k < 3; ++k) xi_dot[k] = p[k], xi_dot[3 + k] = a[k];
  }
  // ∂ξ̇/∂ξ at ξ = 0 (6 × 6, row-major into A): ξ̇_p = exp(ξ_r) v_p = v_p − [v_p]× ξ_r + O(ξ²)
  // gives −[v_p]× in the block (p, r); ξ̇_r as a spherical joint's, −½ [ω]× in (r, r).
  static void chart_rate_jacobian(const Joint&, const double* v, double* A) {
    add_skew(-1.0, v, A + 3, 6);
    add_skew(-0.5, v + 3, A + 6 * 3 + 3, 6);
  }
  // Along the ray q(s) = q_c ⊕ sΔ: p = p_c + R_c s Δ_p turns into B's axes as B turns by
  // exp(sΔ_r), so the rates per unit s are w = (exp(sΔ_r)ᵀ Δ_p, Δ_r), dw/ds = (−Δ_r × w_p, 0).
  static void ray_rates(const Joint&, const double* delta, double s, double* w, double* dw) {
    const Vec3 r(delta[3], delta[4], delta[5]);
    const double angle = s * r.norm();
    const Mat3 E = angle != 0 ? axis_rotation(r.normalized(), angle) : Mat3::Identity();
    const Vec3 wp = E.transpose() * Vec3(delta[0], delta[1], delta[2]), dwp = -r.cross(wp);
    for (int k = 0; k < 3; ++k) w[k] = wp[k], dw[k] = dwp[k], w[3 + k] = r[k], dw[3 + k] = 0;
  }
  static void neutral(double* q) {
    for (int k = 0; k < 7; ++k) q[k] = 0;
    q[3] = 1;
  }
  static constexpr double kRandomHalfRange = 0.5;  // ±0.5 m; orientation uniform
};

}  // namespace femdyn
