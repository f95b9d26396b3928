#include "io/centroidal_mass.hpp"

namespace femdyn {

CentroidalMass CentroidalMass::expressed_in(const Mat3& R, const Vec3& p) const {
  return {mass, R * com + p, R * inertia * R.transpose()};
}

CentroidalMass welded(const CentroidalMass& a, const CentroidalMass& b) {
  const double m = a.mass + b.mass;
  CentroidalMass out;
  out.mass = m;
  out.com = m > 0 ? Vec3((a.mass * a.com + b.mass * b.com) / m) : a.com;
  out.inertia = a.inertia + b.inertia;
  for (const CentroidalMass* part : {&a, &b}) {
    const Vec3 d = part->com - out.com;
    out.inertia += part->mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose());
  }
  return out;
}

Mat3 nearest_physical_inertia(const Mat3& I) {
  const Mat3 sigma = 0.5 * I.trace() * Mat3::Identity() - I;
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(sigma);
  if (eig.eigenvalues().minCoeff() >= 0) return I;
  const Mat3 physical = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
                        eig.eigenvectors().transpose();
  return physical.trace() * Mat3::Identity() - physical;
}

std::string principal_moments_text(const Mat3& I) {
  const Vec3 p = Eigen::SelfAdjointEigenSolver<Mat3>(I).eigenvalues();
  return format_number(p[0]) + ", " + format_number(p[1]) + ", " + format_number(p[2]);
}

}  // namespace femdyn
