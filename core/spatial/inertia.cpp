#include "core/spatial/inertia.hpp"

#include <algorithm>
#include <cmath>

namespace femdyn {

std::optional<std::string> inertia_problem(const Mat3& I, double reference) {
  if (!I.allFinite()) return "inertia has NaN or Inf";
  const double scale = std::max(I.cwiseAbs().maxCoeff(), reference);
  if ((I - I.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) return "inertia is not symmetric";
  const Vec3 p = Eigen::SelfAdjointEigenSolver<Mat3>(I).eigenvalues();  // ascending
  const double tol = 1e-9 * std::max(scale, 1e-300);
  if (p[0] < -tol) return "inertia has a negative principal moment (" + format_number(p[0]) + ")";
  if (p[0] + p[1] < p[2] - tol)
    return "inertia violates the triangle inequality (principal moments " + format_number(p[0]) +
           ", " + format_number(p[1]) + ", " + format_number(p[2]) + ")";
  return std::nullopt;
}

Eigen::Matrix4d pseudo_inertia(double mass, const Vec3& com, const Mat3& I_com) {
  Eigen::Matrix4d P;
  P.topLeftCorner<3, 3>() =
      0.5 * I_com.trace() * Mat3::Identity() - I_com + mass * com * com.transpose();
  P.topRightCorner<3, 1>() = mass * com;
  P.bottomLeftCorner<1, 3>() = mass * com.transpose();
  P(3, 3) = mass;
  return P;
}

std::optional<std::array<Vec3, 4>> equimomental_points(double mass, const Vec3& com,
                                                       const Mat3& I_com) {
  const Eigen::Matrix4d P = pseudo_inertia(mass, com, I_com);
  Eigen::LLT<Eigen::Matrix4d> llt(P);
  if (llt.info() != Eigen::Success) return std::nullopt;
  const Eigen::Matrix4d L = llt.matrixL();
  const Eigen::Vector4d l = L.row(3).transpose();
  const Eigen::Vector4d t = Eigen::Vector4d::Constant(std::sqrt(mass / 4.0));
  const Eigen::Vector4d v = l - t;
  Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
  if (v.squaredNorm() > 0) H -= 2.0 * v * v.transpose() / v.squaredNorm();  // H l = t
  const Eigen::Matrix4d W = L * H.transpose();  // W Wᵀ = P, last row = t
  std::array<Vec3, 4> pts;
  for (int i = 0; i < 4; ++i) pts[i] = W.col(i).head<3>() / W(3, i);
  return pts;
}

}  // namespace femdyn
