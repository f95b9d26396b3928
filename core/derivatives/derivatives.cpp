#include "core/derivatives/derivatives.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics/body_loads.hpp"
#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/joints/rotor.hpp"
#include "core/kinematics/coupling.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/arguments.hpp"
#include "core/model/errors.hpp"

namespace femdyn {
namespace {

// The per-body steps are [[gnu::flatten]]: their small spatial products (6-vector sums, 3 × 3
// blocks) are inlined whatever GCC's size heuristics decide for this file. Left to them, some
// became calls once the sweep moved to inverse_mass.cpp (hand 9.6 → 10.1 µs).

// B = −crm(V)ᵀ I − I crm(V) − H(I V) for I = [[A, [h]×], [[h]×ᵀ, m 1]], V = (ω, v), the map
// B x = V ×* (I x) − I (V × x) + x ×* (I V). Written out by blocks (with the Jacobi identity)
// its right column vanishes:
//   B = [[ [ω]× A − A [ω]× − (h vᵀ + v hᵀ − 2 (v·h) 1) − [A ω + h × v]×,  0 ],
//        [ −2 [m v + ω × h]×,                                            0 ]],
// about 70 operations instead of the 6 × 6 products' 430. With I V = (A ω + h × v, m v + ω × h)
// given (the body's force needs it too), as IV.
VelocityInertia velocity_inertia(const RigidInertia& I, const Vec6& V, const Vec6& IV) {
  const Mat3& A = I.I;
  const Vec3& h = I.h;
  const Vec3 w = V.head<3>(), v = V.tail<3>();
  Mat3 W;  // [ω]× A by columns, so that [ω]× A − A [ω]× = W + Wᵀ (A symmetric)
  for (int j = 0; j < 3; ++j) W.col(j) = cross3(w, A.col(j));
  const double vh2 = 2 * v.dot(h);
  VelocityInertia B;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i)
      B.top(i, j) = W(i, j) + W(j, i) - h[i] * v[j] - v[i] * h[j] + (i == j ? vh2 : 0.0);
  const Vec3 k = IV.head<3>();  // − [A ω + h × v]×
  B.top(0, 1) += k[2], B.top(1, 0) -= k[2];
  B.top(2, 0) += k[1], B.top(0, 2) -= k[1];
  B.top(1, 2) += k[0], B.top(2, 1) -= k[0];
  B.hf = IV.tail<3>();  // m v + ω × h
  return B;
}

// L s: how the world-fixed loads on a body turn when it turns by s (force deviation from a rigid
// wrench): a point load f at x gives (x × (s × f), s × f), a body torque t gives (s × t, 0).
void add_load_turning(const Model& m, const Workspace& ws, DerivativeWorkspace& d) {
  for (Mat63& L : d.Lc) L.setZero();
  for (const PointLoad& l : m.point_loads) {
    const BodyState& B = ws.body[l.body];
    const Vec3 x = B.p + B.R * l.point;
    d.Lc[l.body].topRows<3>() -= skew(x) * skew(l.force);
    d.Lc[l.body].bottomRows<3>() -= skew(l.force);
  }
  for (const BodyTorque& t : m.torques) d.Lc[t.body].topRows<3>() -= skew(t.torque);
}

// Body b's columns S (world axes about the origin) and its inertia I_b there, from its pose.
void columns_and_inertia(const Model& m, const Workspace& ws, DerivativeWorkspace& d, int b) {
  const Joint& J = m.bodies[b].joint;
  const BodyState& Bs = ws.body[b];
  if (moves(J))
    spatial_columns(J, Bs.R, parent_rotation(m, ws.body, b), Bs.p, d.S.data() + J.idx_v);
  d.Ic[b] = inertia_at_origin(m.body_inertia[b], Bs.R, Bs.p);
}

// The same for a joint of several rates (or none), with the columns and the inertia the
// articulated forward dynamics just formed at this q (one rate: articulated_one_rate_body).
void articulated_columns_and_inertia(const Model& m, const Workspace& ws, DerivativeWorkspace& d,
                                     int b) {
  const Joint& J = m.bodies[b].joint;
  for (int k = 0; k < J.nv; ++k) d.S[J.idx_v + k] = ws.subspace[J.idx_v + k];
  d.Ic[b] = ws.articulated[b].I;
}

// Root to leaves for body b, its S and I_b in place: V̄, ā, V, a, the rates' y, δV, z, and its
// own B and f.
[[gnu::flatten]] void forward_body(const Model& m, DerivativeWorkspace& d, int b,
                                   const Vec6& a_base) {
  const Body& body = m.bodies[b];
  const Joint& J = body.joint;
  const Vec6 V_P = body.parent >= 0 ? d.V[body.parent] : Vec6::Zero();
  const Vec6 a_P = body.parent >= 0 ? d.a[body.parent] : a_base;
  Vec6 Vbar = V_P, abar = a_P;
  if (moves(J)) {
    for (int k = 0; k < J.nv; ++k)  // columns fixed in the parent: they do not move with q_J
      if (column_in_parent(J, k)) {
        const int r = J.idx_v + k;
        Vbar += d.S[r] * d.theta_dot[r];
        abar += d.S[r] * d.theta_ddot[r] + cross_motion(V_P, d.S[r]) * d.theta_dot[r];
      }
  }
  Vec6 V = Vbar, a = abar;
  for (int k = 0; k < J.nv; ++k)
    if (!column_in_parent(J, k)) V += d.S[J.idx_v + k] * d.theta_dot[J.idx_v + k];
  for (int k = 0; k < J.nv; ++k) {
    const int r = J.idx_v + k;
    const bool in_parent = column_in_parent(J, k);
    if (!in_parent) a += d.S[r] * d.theta_ddot[r] + cross_motion(V, d.S[r]) * d.theta_dot[r];
    d.dV[r] = cross_motion(Vbar, d.S[r]);
    d.y[r] = -cross_motion(d.S[r], abar) - cross_motion(d.dV[r], Vbar);
    d.z[r] = cross_motion(in_parent ? V_P : V, d.S[r]) - cross_motion(d.S[r], Vbar);
  }
  d.V[b] = V, d.a[b] = a, d.V_bar[b] = Vbar, d.a_bar[b] = abar;
  const Vec6 IV = d.Ic[b] * V;
  d.F[b] = d.Ic[b] * a + cross_force(V, IV);
  d.Bc[b] = velocity_inertia(d.Ic[b], V, IV);
}

// forward_body for a joint of one rate (its column fixed in B), with V, a, S and I_b that the
// articulated forward dynamics just formed at (q, v, q̈): V̄ = V_P, ā = a_P, and since
// V = V_P + S θ̇ and S × S = 0, V × S = V_P × S = δV, so that
//   z = V × S − S × V_P = 2 δV,   y = −S × a_P − δV × V_P.
[[gnu::flatten]] void articulated_one_rate_body(const Model& m, const Workspace& ws,
                                                DerivativeWorkspace& d, int b, const Vec6& a_base) {
  const int p = m.bodies[b].parent, r = m.bodies[b].joint.idx_v;
  const ArticulatedBody& A = ws.articulated[b];
  const Vec6 V_P = p >= 0 ? ws.articulated[p].V : Vec6::Zero();
  const Vec6 a_P = p >= 0 ? ws.articulated[p].a : a_base;
  d.S[r] = A.S;
  d.Ic[b] = A.I;
  d.dV[r] = cross_motion(V_P, A.S);
  d.z[r] = 2 * d.dV[r];
  d.y[r] = cross_motion(a_P, A.S) - cross_motion(d.dV[r], V_P);
  d.V[b] = A.V, d.a[b] = A.a, d.V_bar[b] = V_P, d.a_bar[b] = a_P;
  const Vec6 IV = A.I * A.V;
  d.F[b] = A.I * A.a + cross_force(A.V, IV);  // f_b before its loads, and B_b
  d.Bc[b] = velocity_inertia(A.I, A.V, IV);
}

// The external wrenches subtracted from each body's own force (as Newton–Euler does).
void subtract_loads(const Model& m, const Workspace& ws, DerivativeWorkspace& d) {
  for (const PointLoad& l : m.point_loads) {
    const BodyState& B = ws.body[l.body];
    d.F[l.body] -= wrench_at_origin(B.p + B.R * l.point, l.force);
  }
  for (const BodyTorque& t : m.torques) d.F[t.body].head<3>() -= t.torque;
}

// backward_body for a joint of one rate r (its column fixed in B, so that z_r = 2 δV_r and the
// own pair takes Xq without the rigid part), both pair sets in one walk up the path: for each
// rate a above r, (a, r) from X and (r, a) from u.
[[gnu::flatten]] void backward_one_rate_body(const Model& m, DerivativeWorkspace& d, int b,
                                             MatX& Kq, MatX& Kv) {
  const int r = m.bodies[b].joint.idx_v;
  const RigidInertia& Ic = d.Ic[b];
  const VelocityInertia& Bc = d.Bc[b];
  const Vec6& S = d.S[r];
  Vec6 Xq = Ic * d.y[r] + Bc * d.dV[r];
  if (d.loads) Xq += d.Lc[b] * S.head<3>();
  const Vec6 Xv = 2 * (Ic * d.dV[r]) + Bc * S;
  const Vec6 XqF = Xq + cross_force(S, d.F[b]);
  Kq(r, r) = S.dot(Xq);
  Kv(r, r) = S.dot(Xv);
  const Vec6 uI = Ic * S;
  const Vec3 uB = Bc.transpose_times(S);
  Vec3 uL = Vec3::Zero();
  if (d.loads) uL.noalias() = d.Lc[b].transpose() * S;
  for (int a = m.rate_parent[r]; a >= 0; a = m.rate_parent[a]) {
    const Vec6& Sa = d.S[a];
    Kq(a, r) = Sa.dot(XqF);
    Kv(a, r) = Sa.dot(Xv);
    Kq(r, a) = uI.dot(d.y[a]) + uB.dot(d.dV[a].head<3>()) + uL.dot(Sa.head<3>());
    Kv(r, a) = uI.dot(d.z[a]) + uB.dot(Sa.head<3>());
  }
}

// Leaves to root at body b, its subtree's I^c, B^c, L^c, F complete: the pairs (c, m) with c or
// m a rate of b and the other on b's path to the root (or b's own). For a joint of several rates
// (or none); one rate is backward_one_rate_body.
[[gnu::flatten]] void backward_body(const Model& m, DerivativeWorkspace& d, int b, MatX& Kq,
                                    MatX& Kv) {
  const Joint& J = m.bodies[b].joint;
  const RigidInertia& Ic = d.Ic[b];
  const VelocityInertia& Bc = d.Bc[b];
  for (int k = 0; k < J.nv; ++k) {  // m own: c own or above (b is the deeper)
    const int mr = J.idx_v + k;
    Vec6 Xq = Ic * d.y[mr] + Bc * d.dV[mr];
    if (d.loads) Xq += d.Lc[b] * d.S[mr].head<3>();
    const Vec6 Xv = Ic * d.z[mr] + Bc * d.S[mr];
    const Vec6 XqF = Xq + cross_force(d.S[mr], d.F[b]);  // with the rigid part S_m ×* F_b
    for (int c = J.idx_v + J.nv - 1; c >= 0; c = m.rate_parent[c]) {
      const bool own = c >= J.idx_v;
      const bool moves_with = own && !column_in_parent(J, c - J.idx_v);
      Kq(c, mr) = d.S[c].dot(moves_with ? Xq : XqF);
      Kv(c, mr) = d.S[c].dot(Xv);
    }
  }
  for (int k = 0; k < J.nv; ++k) {  // c own, m strictly above: b is the deeper
    const int c = J.idx_v + k;
    d.uI[c] = Ic * d.S[c];
    d.uB[c] = Bc.transpose_times(d.S[c]);
    if (d.loads) d.uL[c].noalias() = d.Lc[b].transpose() * d.S[c];
    for (int mr = m.rate_parent[J.idx_v]; mr >= 0; mr = m.rate_parent[mr]) {
      double q = d.uI[c].dot(d.y[mr]) + d.uB[c].dot(d.dV[mr].head<3>());
      if (d.loads) q += d.uL[c].dot(d.S[mr].head<3>());
      Kq(c, mr) = q;
      Kv(c, mr) = d.uI[c].dot(d.z[mr]) + d.uB[c].dot(d.S[mr].head<3>());
    }
  }
}

// The composites of b into its parent's.
void accumulate(const Model& m, DerivativeWorkspace& d, int b) {
  const int p = m.bodies[b].parent;
  if (p < 0) return;
  d.Ic[p] += d.Ic[b];
  d.Bc[p] += d.Bc[b];
  d.F[p] += d.F[b];
  if (d.loads) d.Lc[p] += d.Lc[b];
}

// The joints' own forces f(θ, θ̇) enter τ_θ as −f: ∂τ_θ/∂θ −= ∂f/∂θ, ∂τ_θ/∂θ̇ −= ∂f/∂θ̇.
void add_passive(const Model& m, const Workspace& ws, const DerivativeWorkspace& d, MatX& Kq,
                 MatX& Kv) {
  for (int j = 0; j < m.n_theta(); ++j) {
    const Joint& J = m.bodies[m.theta_joint[j]].joint;
    if (J.nv != 1) {  // a spherical or free joint's damper, −c on each rate
      Kv(j, j) += J.damping;
      continue;
    }
    const double th = ws.theta[J.idx_q], w = d.theta_dot[j];
    Kq(j, j) += J.stiffness;  // −∂(−k (θ − θ_rest))/∂θ
    Kv(j, j) += J.damping;
    if (J.friction != 0) {  // −F_c tanh(θ̇/v_s): slope F_c/v_s sech²
      const double t = std::tanh(w / J.friction_velocity);
      Kv(j, j) += J.friction / J.friction_velocity * (1 - t * t);
    }
    if (!J.stop) continue;
    const StopForce s = stop_force(J, th, w);
    if (s.force == 0) continue;  // inside the limits, or the clamp holds it at 0
    const double x = th > J.upper ? th - J.upper : th - J.lower;
    const double sign = th > J.upper ? 1.0 : -1.0;  // f = −k_s x (1 ± d θ̇)
    Kq(j, j) += J.stop_stiffness * (1 + sign * J.stop_dissipation * w);
    Kv(j, j) += J.stop_stiffness * x * sign * J.stop_dissipation;
  }
  add_rotor_bias_rate_derivative(m, d.theta_dot, Kv);  // τ ∋ +h_a
}

// ∂τ_θ/∂θ, ∂τ_θ/∂θ̇ (nθ × nθ) into Kq, Kv.
// With articulated_ready, the articulated forward dynamics has just run at q: the body poses, θ,
// the columns S and the inertias I_b in ws are those at q.
void joint_level(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                 const VecX& qd, const VecX& qdd, MatX& Kq, MatX& Kv,
                 bool articulated_ready = false) {
  const int nb = static_cast<int>(m.bodies.size());
  if (!articulated_ready)
    propagate(m, ws, q, qd, {.jacobian = false, .bias = false, .rows = false});  // poses, θ
  coupling_apply(m, qd, d.theta_dot);
  coupling_apply(m, qdd, d.theta_ddot);
  const Vec6 a_base = gravity_base_acceleration(m);
  for (int b = 0; b < nb; ++b) {
    if (!articulated_ready) {
      columns_and_inertia(m, ws, d, b);
      forward_body(m, d, b, a_base);
    } else if (m.bodies[b].joint.nv == 1) {
      articulated_one_rate_body(m, ws, d, b, a_base);
    } else {
      articulated_columns_and_inertia(m, ws, d, b);
      forward_body(m, d, b, a_base);
    }
  }
  subtract_loads(m, ws, d);
  if (d.loads) add_load_turning(m, ws, d);
  for (int b = nb - 1; b >= 0; --b) {
    if (m.bodies[b].joint.nv == 1)
      backward_one_rate_body(m, d, b, Kq, Kv);
    else
      backward_body(m, d, b, Kq, Kv);
    accumulate(m, d, b);
  }
  add_passive(m, ws, d, Kq, Kv);
}

}  // namespace

std::string derivatives_unsupported(const Model& m) {
  if (!m.constraints.empty() && (m.coupling_level || !m.identity_coupling))
    return "derivatives of a model with closed loops need uncoupled joints (C = I)";
  if (m.coupling_level) return law_derivatives_unsupported(m);
  if (!m.condensable_off_spans || !m.velocity_forces_rigid ||
      m.body_inertia.size() != m.bodies.size())
    return "derivatives need an exact body-level form (no explicit correlation table, rigid "
           "velocity forces)";
  return span_derivatives_unsupported(m);
}

DerivativeWorkspace::DerivativeWorkspace(const Model& m) {
  if (const std::string why = derivatives_unsupported(m); !why.empty())
    throw ModelError(m.where, why);
  const int n = m.n(), nt = m.n_theta(), nb = static_cast<int>(m.bodies.size());
  for (MatX* M : {&dtau_dq, &dtau_dv, &dqdd_dq, &dqdd_dv, &Minv}) M->setZero(n, n);
  qdd = VecX::Zero(n);
  for (auto* v : {&V, &a, &V_bar, &a_bar, &F}) v->assign(nb, Vec6::Zero());
  Ic.assign(nb, RigidInertia{});
  Bc.assign(nb, VelocityInertia{});
  loads = !m.point_loads.empty() || !m.torques.empty();
  Lc.assign(loads ? nb : 0, Mat63::Zero());
  for (auto* v : {&S, &dV, &y, &z, &uI}) v->assign(nt, Vec6::Zero());
  for (auto* v : {&uB, &uL}) v->assign(nt, Vec3::Zero());
  theta_dot = VecX::Zero(nt);
  theta_ddot = VecX::Zero(nt);
  column = VecX::Zero(n);
  if (!m.identity_coupling) {
    Kq.setZero(nt, nt);
    Kv.setZero(nt, nt);
    KC.setZero(nt, n);
  }
  if (!m.springs.empty()) springs.size_for(m);
  if (!m.condensable && !m.coupling_level) spans.size_for(m);  // (a law model: its tree's)
  if (m.coupling_level) law = std::make_unique<LawDerivatives>(m);
  if (!m.constraints.empty()) loops = std::make_unique<LoopDerivatives>(m);
  sweep.plan(m);
}

namespace {

void inverse_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                         const VecX& qd, const VecX& qdd, bool articulated_ready) {
  MatX& Kq = m.identity_coupling ? d.dtau_dq : d.Kq;
  MatX& Kv = m.identity_coupling ? d.dtau_dv : d.Kv;
  Kq.setZero();
  Kv.setZero();
  joint_level(m, ws, d, q, qd, qdd, Kq, Kv, articulated_ready);
  if (!m.springs.empty()) add_spring_derivatives(m, ws, d, Kq, Kv);
  if (!d.spans.elements.empty()) add_span_derivatives(m, ws, d, Kq, Kv);
  if (m.has_rate_damping) d.dtau_dv += m.rate_damping;  // τ += D q̇ (identity coupling only)
  if (m.identity_coupling) return;
  d.KC.noalias() = Kq * m.C;  // ∂τ_q/∂q = Cᵀ (∂τ_θ/∂θ) C
  d.dtau_dq.noalias() = m.C.transpose() * d.KC;
  d.KC.noalias() = Kv * m.C;
  d.dtau_dv.noalias() = m.C.transpose() * d.KC;
}

}  // namespace

void inverse_dynamics_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d,
                                  const VecX& q, const VecX& qd, const VecX& qdd) {
  require_state(m, "inverse_dynamics_derivatives", q, &qd, "qd");
  require_size(m, "inverse_dynamics_derivatives", "qdd", qdd, ArgumentKind::Rate);
  if (m.coupling_level) return law_inverse_derivatives(m, ws, d, q, qd, qdd);
  inverse_derivatives(m, ws, d, q, qd, qdd, false);
}

Status forward_dynamics_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d,
                                    const VecX& q, const VecX& qd, const VecX& tau) {
  require_state(m, "forward_dynamics_derivatives", q, &qd, "qd");
  require_size(m, "forward_dynamics_derivatives", "tau", tau, ArgumentKind::Actuation);
  if (m.coupling_level) return law_forward_derivatives(m, ws, d, q, qd, tau);
  if (d.loops)
    return constrained_forward_dynamics_derivatives(m, ws, d.loops->lws, d, q, qd, tau,
                                                    d.baumgarte);
  const Status st = forward_dynamics(m, ws, q, qd, tau);
  if (!st.ok) return st;
  d.qdd = ws.qdd;
  inverse_derivatives(m, ws, d, q, qd, d.qdd,
                      m.dynamics_route == DynamicsRoute::Articulated);  // poses at q in ws
  inverse_mass_matrix(m, ws, d);
  minus_inverse_mass_times(m, ws, d, d.dtau_dq, d.dqdd_dq);  // ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂·
  minus_inverse_mass_times(m, ws, d, d.dtau_dv, d.dqdd_dv);
  return st;
}

void linearization(const Model& m, const DerivativeWorkspace& d, const VecX& qd, MatX& A, MatX& B) {
  const int n = m.n();
  A.setZero(2 * n, 2 * n);
  B.setZero(2 * n, m.n_actuated());
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = d.dqdd_dq;
  A.bottomRightCorner(n, n) = d.dqdd_dv;
  for (int k = 0; k < m.n_actuated(); ++k)  // B = [0; M⁻¹ S], S = I[:, actuated]
    B.col(k).tail(n) = d.Minv.col(m.actuated[k]);
  A.topLeftCorner(n, n) = chart_rate_jacobian(m, qd);  // each joint type's ∂ξ̇/∂ξ
}

Status linearize_state(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                       const VecX& qd, const VecX& tau, MatX& A, MatX& B) {
  if (Status st = forward_dynamics_derivatives(m, ws, d, q, qd, tau); !st.ok) return st;
  linearization(m, d, qd, A, B);
  for (const auto& [what, x] : {std::pair<const char*, const MatX*>{"A", &A}, {"B", &B}})
    if (!x->allFinite())
      return {false, std::string(what) + " is NaN or Inf (the state overflows double precision)",
              -1, true};
  return {};
}

}  // namespace femdyn
