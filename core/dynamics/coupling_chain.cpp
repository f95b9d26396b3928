#include "core/dynamics/coupling_chain.hpp"

#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/coupled_dynamics.hpp"
#include "core/dynamics/newton_euler.hpp"
#include "core/dynamics/span_inertia.hpp"
#include "core/joints/passive.hpp"
#include "core/joints/rotor.hpp"
#include "core/model/errors.hpp"

namespace femdyn::chain {

namespace {

const VecX kNoActuation;  // the tree is not actuated: τ acts on q, added after the reduction

// g, G, G x, G y, g''[x, y] at q into ws.level; throws where a law is not defined.
CouplingLevelState& level_at(const Model& m, Workspace& ws, const VecX& q, const VecX& x,
                             const VecX& y, bool hessian = false) {
  CouplingLevelState& s = *ws.level;
  if (!evaluate_level(*m.coupling_level, q, x, y, s, hessian)) {
    const CoupledJoint& j = m.coupling_level->coupled[s.failed];
    std::string at;
    for (int k : j.sources)
      at += (at.empty() ? "" : ", ") + m.bodies[m.theta_joint[k]].joint.name + " = " +
            format_number(s.theta[m.coupling_level->theta_q[k]]);
    throw StateError(j.where + ": the law of joint '" + j.name + "' is not defined at " + at +
                     " (a linkage that cannot assemble or is at its dead point)");
  }
  ws.theta = s.theta;
  ws.theta_dot = s.theta_dot;
  return s;
}

// The body states of the tree are this model's.
void share_bodies(Workspace& ws) {
  ws.body = ws.tree->body;
  ws.origin = ws.tree->origin;
}

// y = Gᵀ f over G's pattern: y_a = Σ_t G_ta f_t.
void reduce_force(const CouplingLevelState& s, const VecX& f, VecX& y) {
  y.setZero();
  for (int t = 0; t < static_cast<int>(f.size()); ++t) {
    if (f[t] == 0) continue;
    for (int k = s.g_begin[t]; k < s.g_begin[t + 1]; ++k)
      y[s.g_col[k]] += s.G(t, s.g_col[k]) * f[t];
  }
}

// M^s = Gᵀ M_θ G from the tree's M_θ: M^s_ab = Σ_tu G_ta M_θ,tu G_ub over M_θ's upper triangle
// and G's pattern, each off-diagonal entry once for (t, u) and once for (u, t).
void reduce_mass(Workspace& ws, const CouplingLevelState& s) {
  const MatX& M = ws.tree->Ms;
  ws.Ms.setZero();
  for (int u = 0; u < M.cols(); ++u)
    for (int t = 0; t <= u; ++t) {
      const double m_tu = M(t, u);
      if (m_tu == 0) continue;
      for (int i = s.g_begin[t]; i < s.g_begin[t + 1]; ++i) {
        const int a = s.g_col[i];
        const double w = s.G(t, a) * m_tu;
        for (int j = s.g_begin[u]; j < s.g_begin[u + 1]; ++j) {
          const int b = s.g_col[j];
          ws.Ms(a, b) += w * s.G(u, b);
          if (t != u) ws.Ms(b, a) += w * s.G(u, b);
        }
      }
    }
}

// h = Gᵀ (h_θ + M_θ γ) from the tree's h_θ and M_θ.
void reduce_bias(Workspace& ws, CouplingLevelState& s) {
  s.f_theta = ws.tree->h;
  s.f_theta.noalias() += ws.tree->Ms * s.gamma;
  reduce_force(s, s.f_theta, ws.h);
}

}  // namespace

void evaluate(const Model& m, Workspace& ws, const VecX& q, const VecX& qd, const VecX& tau) {
  CouplingLevelState& s = level_at(m, ws, q, qd, qd);
  Workspace& t = *ws.tree;
  femdyn::evaluate(*m.tree, t, s.theta, s.theta_dot, kNoActuation);
  reduce_mass(ws, s);
  reduce_bias(ws, s);
  reduce_force(s, t.Q, ws.Q);
  if (tau.size()) ws.Q += tau;
  share_bodies(ws);
}

void mass_matrix(const Model& m, Workspace& ws, const VecX& q) {
  CouplingLevelState& s = level_at(m, ws, q, q, q);
  femdyn::mass_matrix(*m.tree, *ws.tree, s.theta);
  reduce_mass(ws, s);
  share_bodies(ws);
}

void evaluate_bias(const Model& m, Workspace& ws, const VecX& q, const VecX& qd) {
  CouplingLevelState& s = level_at(m, ws, q, qd, qd);
  femdyn::evaluate(*m.tree, *ws.tree, s.theta, s.theta_dot, kNoActuation);
  reduce_bias(ws, s);
  share_bodies(ws);
}

// h_θ + M_θ γ is the tree's Newton–Euler at θ̈ = γ without gravity or loads, plus its rotors'
// I_a γ.
void evaluate_bias_by_bodies(const Model& m, Workspace& ws, const VecX& q, const VecX& qd) {
  CouplingLevelState& s = level_at(m, ws, q, qd, qd);
  const Model& tree = *m.tree;
  Workspace& t = *ws.tree;
  newton_euler(tree, t, s.theta, s.theta_dot, &s.gamma, false, s.f_theta);
  if (tree.has_armature) s.f_theta.noalias() += tree.armature_mass * s.gamma;
  add_rotor_bias(tree, s.theta_dot, 1.0, s.f_theta);  // (the tree's q̇ is θ̇)
  reduce_force(s, s.f_theta, ws.h);
  share_bodies(ws);
}

namespace {

// g, G, θ̇ and γ at (q, q̇), or the failure naming the law.
Status level_status(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                    CouplingLevelState*& s) {
  try {
    s = &level_at(m, ws, q, qd, qd);
  } catch (const StateError& e) {
    return {false, e.what()};
  }
  return {};
}

// q̈ from M^s = Gᵀ M_θ G and Q − h = τ − Gᵀ τ_θ(θ, θ̇, θ̈ = γ), τ_θ in wt.tau_theta and M_θ in wt.Ms;
// the Cholesky factor is left in ws.reduced (for the derivatives, core/derivatives/coupling.cpp).
Status solve_reduced(Workspace& ws, CouplingLevelState& s, const VecX& tau) {
  reduce_mass(ws, s);
  reduce_force(s, ws.tree->tau_theta, ws.qdd);
  ws.qdd = -ws.qdd;
  if (tau.size()) ws.qdd += tau;
  share_bodies(ws);
  ws.reduced.compute(ws.Ms);
  if (ws.reduced.info() != Eigen::Success)
    return {false,
            "the mass matrix M^s = Gᵀ M_θ G is not positive definite at this state (the coupling "
            "level loses rank: a law with zero slope in every coordinate it follows?)"};
  ws.reduced.solveInPlace(ws.qdd);
  return {};
}

}  // namespace

// τ_θ(θ, θ̇, γ) = M_θ γ + h_θ − Q_θ is the tree's inverse dynamics at the bias acceleration,
// by its own route, and M_θ its mass matrix.
Status forward_dynamics(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau) {
  CouplingLevelState* s = nullptr;
  if (Status st = level_status(m, ws, q, qd, s); !st.ok) return st;
  Workspace& t = *ws.tree;
  femdyn::inverse_dynamics(*m.tree, t, s->theta, s->theta_dot, s->gamma);
  t.tau_theta = t.tau;
  femdyn::mass_matrix(*m.tree, t, s->theta);
  return solve_reduced(ws, *s, tau);
}

// On a tree with the body-level routes, τ_θ and M_θ come from one pair of sweeps
// (joint_force_sweeps, core/dynamics/coupled_dynamics.hpp) with the spanning elements' forces and
// masses added on θ (core/dynamics/span_inertia.hpp): the bodies' poses and inertias are formed
// once.
Status forward_dynamics_by_bodies(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                                  const VecX& tau) {
  CouplingLevelState* s = nullptr;
  if (Status st = level_status(m, ws, q, qd, s); !st.ok) return st;
  const Model& tree = *m.tree;
  Workspace& t = *ws.tree;
  propagate(tree, t, s->theta, s->theta_dot, {.jacobian = false, .bias = false, .rows = false});
  t.theta_dot = s->theta_dot;
  joint_force_sweeps(tree, t, &s->gamma);
  add_span_forces(tree, t, t.tau_theta);
  add_rotor_bias(tree, s->theta_dot, 1.0, t.tau_theta);
  add_rate_dampers(tree, s->theta_dot, -1.0, t.tau_theta);
  whole_mass_from_composites(tree, t);
  return solve_reduced(ws, *s, tau);
}

void inverse_dynamics(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                      const VecX& qdd) {
  CouplingLevelState& s = level_at(m, ws, q, qd, qd);
  s.theta_ddot = s.gamma;
  s.theta_ddot.noalias() += s.G * qdd;  // θ̈ = G q̈ + γ
  femdyn::inverse_dynamics(*m.tree, *ws.tree, s.theta, s.theta_dot, s.theta_ddot);
  reduce_force(s, ws.tree->tau, ws.tau);
  share_bodies(ws);
}

void propagate_bilinear(const Model& m, Workspace& ws, const VecX& q, const VecX& x, const VecX& y,
                        KinematicsRequest request) {
  CouplingLevelState& s = level_at(m, ws, q, x, y);
  ws.theta_dot_y = s.theta_dot_y;
  Workspace& t = *ws.tree;
  // T_θ is needed for the bias too (T_θ γ).
  femdyn::propagate_bilinear(*m.tree, t, s.theta, s.theta_dot, s.theta_dot_y,
                             {.jacobian = true, .bias = request.bias, .rows = true});
  if (request.jacobian) {
    ws.Jw.noalias() = t.Jw * s.G;
    ws.Jv.noalias() = t.Jv * s.G;
    if (request.rows) ws.T.noalias() = t.T * s.G;
  }
  if (request.bias) {
    ws.bias = t.bias;
    ws.bias.noalias() += t.T * s.gamma;  // T'_θ[G x, G y] + T_θ g''[x, y]
    ws.u_dot = t.u_dot;
  }
  share_bodies(ws);
  if (request.bias)  // at q̈ = 0 the tree moves with θ̈ = γ: each body's bias gains J_θ,b γ
    for (std::size_t b = 0; b < ws.body.size(); ++b) {
      ws.body[b].alpha.noalias() += t.Jw.middleRows<3>(3 * b) * s.gamma;
      ws.body[b].a.noalias() += t.Jv.middleRows<3>(3 * b) * s.gamma;
    }
}

std::vector<MatX> transform_hessian(const Model& m, Workspace& ws, const VecX& q) {
  const VecX zero = VecX::Zero(m.n());
  CouplingLevelState& s = level_at(m, ws, q, zero, zero, true);
  Workspace& t = *ws.tree;
  std::vector<MatX> H = femdyn::transform_hessian(*m.tree, t, s.theta);
  femdyn::propagate(*m.tree, t, s.theta, VecX::Zero(m.n_theta()),
                    {.jacobian = true, .bias = false});
  for (std::size_t i = 0; i < H.size(); ++i) {
    MatX Hi = s.G.transpose() * H[i] * s.G;  // T'_θ[G e_b, G e_c]
    for (int j = 0; j < m.n_theta(); ++j)
      if (t.T(i, j) != 0) Hi += t.T(i, j) * s.H[j];  // + T_θ ∂²θ/∂q_b∂q_c
    H[i] = std::move(Hi);
  }
  share_bodies(ws);
  return H;
}

std::vector<MatX> third_order_tensor(const Model& m, Workspace& ws, const VecX& q) {
  const VecX zero = VecX::Zero(m.n());
  CouplingLevelState& s = level_at(m, ws, q, zero, zero, true);
  Workspace& t = *ws.tree;
  const std::vector<MatX> Dt = femdyn::third_order_tensor(*m.tree, t, s.theta);
  femdyn::mass_matrix(*m.tree, t, s.theta);
  const int n = m.n(), nt = m.n_theta();
  std::vector<MatX> inner(nt);  // per θ row i: Gᵀ D^θ_i G + Σ_l M_θ(i, l) H_l
  for (int i = 0; i < nt; ++i) {
    inner[i] = s.G.transpose() * Dt[i] * s.G;
    for (int l = 0; l < nt; ++l)
      if (t.Ms(i, l) != 0) inner[i] += t.Ms(i, l) * s.H[l];
  }
  std::vector<MatX> D(n, MatX::Zero(n, n));
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < nt; ++i)
      if (s.G(i, a) != 0) D[a] += s.G(i, a) * inner[i];
  share_bodies(ws);
  return D;
}

void joint_state(const Model& m, Workspace& ws, const VecX& q, const VecX& qd) {
  level_at(m, ws, q, qd, qd);  // sets ws.theta, ws.theta_dot
}

Energy energy(const Model& m, Workspace& ws, const VecX& q, const VecX& qd) {
  CouplingLevelState& s = level_at(m, ws, q, qd, qd);
  const Energy E = femdyn::energy(*m.tree, *ws.tree, s.theta, s.theta_dot);
  share_bodies(ws);
  return E;
}

}  // namespace femdyn::chain
