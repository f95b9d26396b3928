// Rotations for the joints whose configuration is a unit quaternion (spherical, free).
//   Quaternion order (w, x, y, z), w the scalar part; R(q) rotates B's axes into the joint frame.
//   exp(ξ): the rotation by |ξ| about ξ/|ξ| (a rotation vector), log its inverse on |ξ| < π.
//   Local chart around R_c: R = R_c exp(ξ). With ω the angular velocity in B's axes
//   (Ṙ = R [ω]×), ξ̇ = J_r(ξ)⁻¹ ω, the inverse right Jacobian of SO(3):
//     J_r(ξ)⁻¹ = 1 + ½ [ξ]× + (1/θ² − (1 + cos θ) / (2 θ sin θ)) [ξ]×²,   θ = |ξ|.
#pragma once
#include <cmath>

#include "core/spatial/math.hpp"

namespace femdyn {

// R(q) for q = (w, x, y, z) at q[0..3] (unit).
inline Mat3 quaternion_rotation(const double* q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
}

// q ⊗ exp(ξ), normalised, into out (may alias q).
inline void quaternion_integrate(const double* q, const double* xi, double* out) {
  const Vec3 x(xi[0], xi[1], xi[2]);
  const double angle = x.norm();
  Eigen::Quaterniond e = Eigen::Quaterniond::Identity();
  if (angle > 0) e = Eigen::Quaterniond(Eigen::AngleAxisd(angle, x / angle));
  Eigen::Quaterniond r = Eigen::Quaterniond(q[0], q[1], q[2], q[3]) * e;
  r.normalize();
  if (r.w() < 0) r.coeffs() *= -1;  // one of ±q: w ≥ 0
  out[0] = r.w(), out[1] = r.x(), out[2] = r.y(), out[3] = r.z();
}

// ξ = log(R(q0)ᵀ R(q1)): the rotation vector from q0 to q1 (|ξ| ≤ π).
inline Vec3 quaternion_difference(const double* q0, const double* q1) {
  const Eigen::Quaterniond a(q0[0], q0[1], q0[2], q0[3]), b(q1[0], q1[1], q1[2], q1[3]);
  Eigen::Quaterniond d = a.conjugate() * b;
  if (d.w() < 0) d.coeffs() *= -1;
  const double s = d.vec().norm();
  if (s < 1e-300) return Vec3::Zero();
  const double angle = 2 * std::atan2(s, d.w());
  return d.vec() * (angle / s);
}

// J_r(ξ)⁻¹ ω.
inline Vec3 inverse_right_jacobian_times(const Vec3& xi, const Vec3& w) {
  const double t = xi.norm();
  const Vec3 xw = xi.cross(w);
  // 1/θ² − (1 + cos θ)/(2 θ sin θ) = 1/12 + θ²/720 + … near 0
  const double c =
      t < 1e-4 ? 1.0 / 12 + t * t / 720 : 1 / (t * t) - (1 + std::cos(t)) / (2 * t * std::sin(t));
  return w + 0.5 * xw + c * xi.cross(xw);
}

// A += s [v]× on the 3 × 3 block at A of a row-major matrix with this row stride.
inline void add_skew(double s, const double* v, double* A, int stride) {
  A[1] -= s * v[2], A[2] += s * v[1];
  A[stride] += s * v[2], A[stride + 2] -= s * v[0];
  A[2 * stride] -= s * v[1], A[2 * stride + 1] += s * v[0];
}

}  // namespace femdyn
