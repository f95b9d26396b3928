// Small 3D helpers shared by the kinematic levels and the elements.
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <string>

namespace femdyn {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

// a × b for 3-vectors (or 3-blocks), spelled out: in the long per-body recursions GCC stops
// inlining Eigen's cross(), and a call costs more than the product.
template <class A, class B>
[[gnu::always_inline]] inline Vec3 cross3(const Eigen::MatrixBase<A>& a,
                                          const Eigen::MatrixBase<B>& b) {
  return Vec3(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

// [a]x, the cross-product matrix: skew(a) * b = a x b.
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}

// URDF convention: R = Rz(yaw) * Ry(pitch) * Rx(roll).
inline Mat3 rpy_to_rotation(const Vec3& rpy) {
  using Eigen::AngleAxisd;
  return (AngleAxisd(rpy.z(), Vec3::UnitZ()) * AngleAxisd(rpy.y(), Vec3::UnitY()) *
          AngleAxisd(rpy.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

// Rotation by angle about a unit axis (Rodrigues).
inline Mat3 axis_rotation(const Vec3& unit_axis, double angle) {
  return Eigen::AngleAxisd(angle, unit_axis).toRotationMatrix();
}

// A(i, j) = A(j, i) below the diagonal, in square tiles so that the strided reads stay in cache.
// Rows of a large A a power of two apart (n = 512: 4 KiB) fall in one L1 set, whose 8 ways a
// 32-row tile overflows: tiles of 8 from n = 256 up (n = 512: 2× faster than 32, n = 500 within
// 10 %), of 32 below, where they are the faster.
inline void mirror_upper(MatX& A) {
  const Eigen::Index n = A.rows(), kTile = n >= 256 ? 8 : 32;
  for (Eigen::Index j0 = 0; j0 < n; j0 += kTile)
    for (Eigen::Index i0 = j0; i0 < n; i0 += kTile)
      for (Eigen::Index j = j0; j < std::min(j0 + kTile, n); ++j)
        for (Eigen::Index i = std::max(i0, j + 1); i < std::min(i0 + kTile, n); ++i)
          A(i, j) = A(j, i);
}

// m(|r|² 1 − r rᵀ) = m [r]xᵀ[r]x: the inertia of a point mass m at r about the origin, the term
// of the parallel-axis theorem (I_o = I_c + m [c]xᵀ[c]x).
inline Mat3 point_inertia(double m, const Vec3& r) {
  return m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
}

// ‖x‖∞, the largest |x_ij| (0 for an empty x).
template <class Derived>
double max_abs(const Eigen::MatrixBase<Derived>& x) {
  return x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
}

// ‖a − b‖∞ / max(‖b‖∞, floor): the error of a relative to the reference b. `floor` keeps it
// meaningful where b vanishes; with floor 0 and b = 0 it is the absolute error ‖a‖∞.
template <class DerivedA, class DerivedB>
double relative_error(const Eigen::MatrixBase<DerivedA>& a, const Eigen::MatrixBase<DerivedB>& b,
                      double floor) {
  const double scale = std::max(max_abs(b), floor), d = max_abs(a - b);
  return scale > 0 ? d / scale : d;
}

// A number for messages: 6 significant digits (std::to_string would print 1e-9 as 0.000000),
// or any one-number printf conversion.
inline std::string format_number(double x, const char* spec = "%.6g") {
  char buf[48];
  std::snprintf(buf, sizeof buf, spec, x);
  return buf;
}

// Three significant digits, for reports and diagnoses.
inline std::string format_short(double x) { return format_number(x, "%.3g"); }
// Three significant digits with an exponent, for errors and tolerances: "1.23e-09".
inline std::string format_sci(double x) { return format_number(x, "%.2e"); }

// A duration for a person: "0.4 s", "12 min", "3.1 h", "2.5 days".
inline std::string format_duration(double seconds) {
  if (!(seconds < 120)) {
    if (seconds < 7200) return format_number(seconds / 60, "%.3g") + " min";
    if (seconds < 172800) return format_number(seconds / 3600, "%.3g") + " h";
    return format_number(seconds / 86400, "%.3g") + " days";
  }
  return format_number(seconds, "%.2g") + " s";
}

}  // namespace femdyn
