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
  // Choose by operation count: the dense M T and Tᵀ (M T), against 6 x 6 x p_b and 6 x p_b²
  // per body (plus the gather and scatter, about as much again).
  const double n = m.n(), dense = (m.n_u() * n + static_cast<double>(m.M.nonZeros())) * n;
  double by_body = 0;
  for (const auto& c : m.body_coords) {
    const double p = static_cast<double>(c.size());
    by_body += 2 * (36 * p + 6 * p * p);
  }
  m.condensed = m.condensable && by_body < dense;
}

}  // namespace femdyn
