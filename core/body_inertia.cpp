#include "core/body_inertia.hpp"

#include <algorithm>

namespace femdyn {
namespace {

// X_e for body orientation R: columns (ω_b, v_b), rows the element's local DOFs.
MatX twist_map(const Element& e, const Mat3& R) {
  const auto ns = e.nodes();
  MatX X = MatX::Zero(e.local_dof_count(), 6);
  for (std::size_t i = 0; i < ns.size(); ++i) {
    X.block<3, 3>(6 * i, 0) = -R * skew(ns[i].position);
    X.block<3, 3>(6 * i, 3) = R;
    X.block<3, 3>(6 * i + 3, 0) = Mat3::Identity();
  }
  return X;
}

}  // namespace

void condense_body_inertia(Model& m) {
  const int nb = static_cast<int>(m.bodies.size());
  m.body_inertia.assign(nb, Mat6::Zero());
  m.condensable = !m.explicit_table;
  // Λ_b at the rest orientation and at a tilted one: equal iff orientation-independent.
  const Mat3 tilt = rpy_to_rotation(Vec3(0.3, -0.7, 1.1));
  for (const ElementEntry& e : m.elements) {
    const MatX me = e.element->local_mass();
    const MatX X0 = twist_map(*e.element, Mat3::Identity()), X1 = twist_map(*e.element, tilt);
    const Mat6 L0 = X0.transpose() * me * X0, L1 = X1.transpose() * me * X1;
    if ((L0 - L1).cwiseAbs().maxCoeff() > 1e-12 * std::max(L0.cwiseAbs().maxCoeff(), 1e-300))
      m.condensable = false;
    m.body_inertia[e.body] += L0;
  }
  // The coordinates that move each body: those of the joints on its path, through C.
  m.body_coords.assign(nb, {});
  for (int b = 0; b < nb; ++b) {
    const Body& B = m.bodies[b];
    std::vector<bool> moves(m.n(), false);
    if (B.parent >= 0)
      for (int a : m.body_coords[B.parent]) moves[a] = true;
    if (B.joint.theta >= 0)
      for (int a = 0; a < m.n(); ++a)
        if (m.C(B.joint.theta, a) != 0) moves[a] = true;
    for (int a = 0; a < m.n(); ++a)
      if (moves[a]) m.body_coords[b].push_back(a);
  }
  // Choose by operation count: the dense M T and Tᵀ (M T), against the composite recursion
  // (about 300 operations a body to move Λ_b, 12 per joint on its path) and, with a coupling,
  // the reduction Cᵀ M_θ C.
  const double n = m.n(), nt = m.n_theta();
  const double dense = (m.n_u() * n + static_cast<double>(m.M.nonZeros())) * n;
  double by_body = m.identity_coupling ? 0 : 2 * nt * nt * n;
  for (const auto& c : m.body_coords) by_body += 300 + 12 * static_cast<double>(c.size());
  m.condensed = m.condensable && by_body < dense;
}

MassProperties body_mass_properties(const Model& m, int body) {
  MassProperties sum;
  Vec3 first_moment = Vec3::Zero();
  for (const ElementEntry& e : m.elements) {
    if (e.body != body) continue;
    const MassProperties p = e.element->mass_properties();
    sum.mass += p.mass;
    first_moment += p.mass * p.com;
    sum.inertia_origin += p.inertia_origin;
  }
  if (sum.mass > 0) sum.com = first_moment / sum.mass;
  return sum;
}

void composite_mass(const Model& m, Workspace& ws) {
  const int nb = static_cast<int>(m.bodies.size());
  // Λ_b^O into the composites, leaves to root (children come after their parents).
  for (int b = 0; b < nb; ++b) ws.composite[b].setZero();
  for (int b = nb - 1; b >= 0; --b) {
    const Mat3& R = ws.body[b].R;
    const Mat6& L = m.body_inertia[b];
    const Mat3 A = R * L.topLeftCorner<3, 3>() * R.transpose();
    const Mat3 B = R * L.topRightCorner<3, 3>() * R.transpose();
    const Mat3 D = R * L.bottomRightCorner<3, 3>() * R.transpose();
    const Mat3 P = skew(ws.body[b].p);
    // Xᵀ [[A, B], [Bᵀ, D]] X with X = [[I, 0], [−P, I]] and Pᵀ = −P.
    const Mat3 BP = B * P, DP = D * P;
    Mat6& I = ws.composite[b];
    I.topLeftCorner<3, 3>() += A - BP - BP.transpose() - P * DP;
    I.topRightCorner<3, 3>() += B + P * D;
    I.bottomLeftCorner<3, 3>() += B.transpose() - DP;
    I.bottomRightCorner<3, 3>() += D;
    if (m.bodies[b].parent >= 0) ws.composite[m.bodies[b].parent] += I;
    // The joint's motion subspace (world axes, about the origin).
    const Joint& j = m.bodies[b].joint;
    Vec6& S = ws.subspace[b];
    const Vec3 s = ws.body[b].R * j.axis;
    if (j.type == JointType::Revolute)
      S << s, ws.body[b].p.cross(s);
    else
      S << Vec3::Zero(), s;
  }
  // M_θ(i, k) = S_kᵀ I^c_b S_i along the path of b.
  MatX& Mt = m.identity_coupling ? ws.Ms : ws.Mtheta;
  Mt.setZero();
  for (int b = 0; b < nb; ++b) {
    const int i = m.bodies[b].joint.theta;
    if (i < 0) continue;
    const Vec6 F = ws.composite[b] * ws.subspace[b];
    for (int a = b; a >= 0; a = m.bodies[a].parent) {
      const int k = m.bodies[a].joint.theta;
      if (k < 0) continue;
      Mt(k, i) = Mt(i, k) = ws.subspace[a].dot(F);
    }
  }
  if (!m.identity_coupling) ws.Ms.noalias() = m.C.transpose() * (ws.Mtheta * m.C);
}

}  // namespace femdyn
