#include "core/dynamics/body_inertia.hpp"

#include <algorithm>

#include "core/dynamics/span_inertia.hpp"
#include "core/joints/kernel.hpp"
#include "core/model/limits.hpp"

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

// The Element contract for velocity forces: under a rigid motion (ω, v) of its body, the
// element's g_e(u̇_e, u̇_e) = g_e(X ξ, X ξ) does the work of a rigid body's gyroscopic term,
//   Xᵀ g_e(X ξ, X ξ) = (ω × J ω, 0),   J = Σ of m_e's rotation-rotation blocks,
// so that the articulated recursion's V ×* Λ V is the same force. Checked at two twists.
bool gyroscopic_is_rigid(const Element& e, const MatX& me) {
  const MatX X = twist_map(e, Mat3::Identity());
  Mat3 J = Mat3::Zero();
  const int k = static_cast<int>(e.nodes().size());
  for (int i = 0; i < k; ++i)
    for (int l = 0; l < k; ++l) J += me.block<3, 3>(6 * i + 3, 6 * l + 3);
  for (const Vec6& xi :
       {Vec6(0.3, -1.1, 0.7, 0.2, 0.5, -0.4), Vec6(-0.9, 0.4, 1.3, -0.6, 0.1, 0.8)}) {
    const VecX x = X * xi;
    VecX g = VecX::Zero(x.size());
    e.add_velocity_force(x, x, g);
    Vec6 expected = Vec6::Zero();
    expected.head<3>() = xi.head<3>().cross(J * xi.head<3>());
    const Vec6 got = X.transpose() * g;
    const double scale = std::max(J.cwiseAbs().maxCoeff() * xi.head<3>().squaredNorm(), 1e-300);
    if ((got - expected).cwiseAbs().maxCoeff() > 1e-12 * scale) return false;
  }
  return true;
}

}  // namespace

void condense_body_inertia(Model& m) {
  const int nb = static_cast<int>(m.bodies.size());
  std::vector<Mat6> L(nb, Mat6::Zero());
  m.condensable = !m.explicit_table;
  bool spans = false;
  m.velocity_forces_rigid = true;
  // Λ_b at the rest orientation and at a tilted one: equal iff orientation-independent.
  const Mat3 tilt = rpy_to_rotation(Vec3(0.3, -0.7, 1.1));
  for (const ElementEntry& e : m.elements) {
    const MatX me = e.element->local_mass();
    for (Eigen::Index k = 0; k < me.size(); ++k)
      check_magnitude(me.data()[k], e.where, "element mass matrix entry");
    if (e.spans) {  // not rigid with one body: only the node-level route is exact
      spans = true;
      continue;
    }
    const MatX X0 = twist_map(*e.element, Mat3::Identity()), X1 = twist_map(*e.element, tilt);
    const Mat6 L0 = X0.transpose() * me * X0, L1 = X1.transpose() * me * X1;
    if ((L0 - L1).cwiseAbs().maxCoeff() > 1e-12 * std::max(L0.cwiseAbs().maxCoeff(), 1e-300))
      m.condensable = false;
    L[e.body] += L0;
    if (!gyroscopic_is_rigid(*e.element, me)) m.velocity_forces_rigid = false;
  }
  // Each Λ_b in the rigid form [[I, [h]×], [[h]×ᵀ, m 1]], as every physical element gives.
  m.body_inertia.assign(nb, RigidInertia{});
  for (int b = 0; b < nb; ++b) {
    RigidInertia& r = m.body_inertia[b];
    r.m = L[b](3, 3);
    r.h = Vec3(L[b](2, 4), L[b](0, 5), L[b](1, 3));
    r.I = L[b].topLeftCorner<3, 3>();
    if ((r.matrix() - L[b]).cwiseAbs().maxCoeff() >
        1e-12 * std::max(L[b].cwiseAbs().maxCoeff(), 1e-300))
      m.condensable = false;
  }
  m.condensable_off_spans = m.condensable;  // Λ_b exact for the elements rigid with b
  if (spans) m.condensable = false;
}

std::vector<MassProperties> body_mass_properties(const Model& m) {
  std::vector<MassProperties> sum(m.bodies.size());
  std::vector<Vec3> first_moment(m.bodies.size(), Vec3::Zero());
  for (const ElementEntry& e : m.elements) {
    if (e.spans) continue;  // a spanning element moves with no one body
    const MassProperties p = e.element->mass_properties();
    sum[e.body].mass += p.mass;
    first_moment[e.body] += p.mass * p.com;
    sum[e.body].inertia_origin += p.inertia_origin;
  }
  for (std::size_t b = 0; b < sum.size(); ++b)
    if (sum[b].mass > 0) sum[b].com = first_moment[b] / sum[b].mass;
  return sum;
}

MassProperties body_mass_properties(const Model& m, int body) {
  MassProperties sum;
  Vec3 first_moment = Vec3::Zero();
  for (const ElementEntry& e : m.elements) {
    if (e.body != body || e.spans) continue;  // a spanning element moves with no one body
    const MassProperties p = e.element->mass_properties();
    sum.mass += p.mass;
    first_moment += p.mass * p.com;
    sum.inertia_origin += p.inertia_origin;
  }
  if (sum.mass > 0) sum.com = first_moment / sum.mass;
  return sum;
}

void composite_inertias(const Model& m, Workspace& ws) {
  const int nb = static_cast<int>(m.bodies.size());
  for (int b = 0; b < nb; ++b)
    ws.composite[b] = inertia_at_origin(m.body_inertia[b], ws.body[b].R, ws.body[b].p);
  for (int b = nb - 1; b >= 0; --b)  // children come after their parents
    if (m.bodies[b].parent >= 0) ws.composite[m.bodies[b].parent] += ws.composite[b];
}

void composite_mass(const Model& m, Workspace& ws) {
  const int nb = static_cast<int>(m.bodies.size());
  composite_inertias(m, ws);
  for (int b = 0; b < nb; ++b)
    if (const Joint& J = m.bodies[b].joint; moves(J))
      spatial_columns(J, ws.body[b].R, parent_rotation(m, ws.body, b), ws.body[b].p,
                      ws.subspace.data() + J.idx_v);
  whole_mass_from_composites(m, ws);
}

void whole_mass_from_composites(const Model& m, Workspace& ws) {
  if (ws.Ms.rows() != m.n()) ws.Ms.setZero(m.n(), m.n());  // first use only
  if (!m.spanning_masses.empty()) ws.Ms.setZero();         // their entries lie off the paths
  mass_from_composites(m, ws);
  mirror_upper(ws.Ms);  // (with the rotor inertia on its diagonal)
  add_span_mass(m, ws);
}

namespace {

// Calls f(k, i, M_θ(k, i)) for every rate i (of body b = theta_joint[i]) and every rate
// k = i, λ(i), λ(λ(i)), … on its path: the entries of M_θ's upper triangle (k ≤ i),
// M_θ(k, i) = S_kᵀ I^c_b S_i.
template <class F>
void for_path_entries(const Model& m, const Workspace& ws, F&& f) {
  for (int i = 0; i < m.n_theta(); ++i) {
    const Vec6 F_i = ws.composite[m.theta_joint[i]] * ws.subspace[i];
    for (int k = i; k >= 0; k = m.rate_parent[k]) f(k, i, ws.subspace[k].dot(F_i));
  }
}

// Calls f(i, i, I_a G²) for every rate i whose joint has a rotor: M_θ's diagonal rotor terms.
template <class F>
void for_rotor_entries(const Model& m, F&& f) {
  for (int i = 0; i < m.n_theta(); ++i)
    if (const double r = m.bodies[m.theta_joint[i]].joint.reflected_inertia; r != 0) f(i, i, r);
}

}  // namespace

void mass_from_composites(const Model& m, Workspace& ws) {
  if (m.identity_coupling) {
    // M^s(k, i) = S_kᵀ I^c_b S_i for the rates k on the path of i (k ≤ i: the upper
    // triangle, column i written contiguously). The entries off every path are structural
    // zeros, written as zeros when the Workspace is made and never touched: no n² clearing.
    for_path_entries(m, ws, [&](int k, int i, double v) { ws.Ms(k, i) = v; });
    if (m.has_armature) for_rotor_entries(m, [&](int k, int i, double v) { ws.Ms(k, i) += v; });
    return;
  }
  // With couplings, M^s = Cᵀ M_θ C = Σ_{k,i} C_kᵀ M_θ(k, i) C_i over the rows C_k of C: each
  // path entry M_θ(k, i) (k an ancestor rate of i, or i itself) is scattered through the
  // non-zeros of rows k and i, once for (k, i) and once for (i, k). O(Σ depth · nnz²) and
  // symmetric as built; no M_θ is formed.
  ws.Ms.setZero();
  const auto scatter = [&](int k, int i, double v) {
    for (SpRowMat::InnerIterator ck(m.C_sparse, k); ck; ++ck)
      for (SpRowMat::InnerIterator ci(m.C_sparse, i); ci; ++ci) {
        const double w = ck.value() * v * ci.value();
        ws.Ms(ck.col(), ci.col()) += w;
        if (k != i) ws.Ms(ci.col(), ck.col()) += w;
      }
  };
  for_path_entries(m, ws, scatter);
  if (m.has_armature) for_rotor_entries(m, scatter);
}

}  // namespace femdyn
