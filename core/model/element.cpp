#include "core/model/element.hpp"

namespace femdyn {

Mat3 MassProperties::inertia_com() const {
  // Parallel axis: I_o = I_c + m [c]xᵀ[c]x.
  return inertia_origin - point_inertia(mass, com);
}

MassProperties Element::mass_properties() const {
  // Under a rigid motion with body twist (ω, v) (body frame, body at rest orientation):
  //   node translation rate = v + ω × r = v − [r]x ω,   rotation rate = ω.
  const auto ns = nodes();
  const int k = static_cast<int>(ns.size());
  MatX X = MatX::Zero(kNodeDofs * k, 6);  // columns: ω (0..2), v (3..5)
  for (int i = 0; i < k; ++i) {
    X.block<3, 3>(6 * i, 0) = -skew(ns[i].position);
    X.block<3, 3>(6 * i, 3) = Mat3::Identity();
    X.block<3, 3>(6 * i + 3, 0) = Mat3::Identity();
  }
  const Eigen::Matrix<double, 6, 6> S = X.transpose() * local_mass() * X;
  // Spatial inertia about the origin: [[I_o, m[c]x], [m[c]xᵀ, m 1]].
  MassProperties p;
  p.mass = S.block<3, 3>(3, 3).trace() / 3.0;
  const Mat3 mc = S.block<3, 3>(0, 3);  // m [c]x
  p.com = p.mass > 0 ? Vec3(Vec3(mc(2, 1), mc(0, 2), mc(1, 0)) / p.mass) : Vec3(Vec3::Zero());
  p.inertia_origin = S.block<3, 3>(0, 0);
  return p;
}

void add_gyroscopic(const Mat3& J, const Vec3& x_omega, const Vec3& y_omega,
                    Eigen::Ref<VecX> g_rot3) {
  g_rot3 += x_omega.cross(J * y_omega);
}

}  // namespace femdyn
