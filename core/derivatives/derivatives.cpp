#include "core/derivatives/derivatives.hpp"

#include <algorithm>
#include <cmath>

#include "core/articulated.hpp"
#include "core/body_loads.hpp"
#include "core/coupling.hpp"
#include "core/equations.hpp"
#include "core/errors.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics.hpp"

namespace femdyn {
namespace {

// Up to this n, ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂· as products with (M^s)⁻¹; above, by the factorisation eight
// columns at a time. Measured crossover: chain64 123 µs dense against 141 µs, chain128 648 µs
// against 506 µs.
constexpr int kDenseProductSize = 96;

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
void forward_body(const Model& m, DerivativeWorkspace& d, int b, const Vec6& a_base) {
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
void articulated_one_rate_body(const Model& m, const Workspace& ws, DerivativeWorkspace& d, int b,
                               const Vec6& a_base) {
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
void backward_one_rate_body(const Model& m, DerivativeWorkspace& d, int b, MatX& Kq, MatX& Kv) {
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
// m a rate of b and the other on b's path to the root (or b's own).
void backward_body(const Model& m, DerivativeWorkspace& d, int b, MatX& Kq, MatX& Kv) {
  const Joint& J = m.bodies[b].joint;
  if (J.nv == 1) return backward_one_rate_body(m, d, b, Kq, Kv);
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
    if (J.nv != 1) continue;
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
    backward_body(m, d, b, Kq, Kv);
    accumulate(m, d, b);
  }
  add_passive(m, ws, d, Kq, Kv);
}

// x ← (M^s)⁻¹ x by the factorisation forward_dynamics left.
void solve_column(const Model& m, Workspace& ws, VecX& x) {
  if (m.dynamics_route == DynamicsRoute::Articulated)
    articulated_solve(m, ws, x);
  else
    ws.solver.solve_in_place(x);
}

// Y ← −(M^s)⁻¹ Y column by column (sign −1), or (M^s)⁻¹ Y.
void solve_columns(const Model& m, Workspace& ws, DerivativeWorkspace& d, MatX& Y, double sign) {
  for (Eigen::Index k = 0; k < Y.cols(); ++k) {
    d.column = sign * Y.col(k);
    solve_column(m, ws, d.column);
    Y.col(k) = d.column;
  }
}

// (M^s)⁻¹ into d.Minv in O(n · bodies) from the articulated factorisation forward_dynamics left
// in ws: articulated_solve applied to all n unit vectors at once. Leaves to root, the unit
// vectors of a subtree's rates are the only ones with articulated forces below it, so one 6 × n
// matrix P holds every body's (its subtree's columns): u = e − Sᵀ P, P += U D⁻¹ u on them. Root
// to leaves, rows r of the joint: x = D⁻¹ u − D⁻¹ Uᵀ a_parent, a = a_parent + S x, on the
// columns from the joint's first rate on (the upper triangle; the rest by symmetry). Row r of
// (M^s)⁻¹ is formed as column r (M^s is symmetric), so that every access is contiguous. Only the
// rates of the body's block of (M^s)⁻¹ (block_first, block_end) are formed: the rest is zero.
void inverse_mass_sweep(const Model& m, const Workspace& ws, DerivativeWorkspace& d) {
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  MatX& X = d.Minv;
  d.P.setZero();
  for (int b = nb - 1; b >= 0; --b) {
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    const int r0 = J.idx_v, cnt = d.sub_count[b], after = d.block_end[b] - r0 - cnt;
    auto Pb = d.P.middleCols(r0, cnt);
    for (int k = 0; k < J.nv; ++k) {
      const Vec6 minus_S = -(J.nv == 1 ? ws.articulated[b].S : ws.subspace[r0 + k]);
      auto u = X.col(r0 + k);
      u.segment(r0, cnt).noalias() = Pb.transpose() * minus_S;
      u[r0 + k] += 1.0;
      u.segment(r0 + cnt, after).setZero();
    }
    if (m.bodies[b].parent < 0) continue;
    for (int k = 0; k < J.nv; ++k) {
      const Vec6 K = J.nv == 1 ? Vec6(ws.articulated[b].U / ws.articulated[b].d)
                               : ws.articulated_rate[r0 + k].K;
      Pb.noalias() += K * X.col(r0 + k).segment(r0, cnt).transpose();
    }
  }
  for (int b = 0; b < nb; ++b) {
    const Body& body = m.bodies[b];
    const Joint& J = body.joint;
    const int p = body.parent, ps = p >= 0 ? d.slot[p] : -1, s = d.slot[b];
    if (!moves(J)) {  // a fixed joint passes its parent's accelerations on
      if (s < 0 || s == ps) continue;
      const int c0 = d.sub_first[b], L = d.block_end[b] - c0;
      if (ps >= 0)
        d.A.middleCols(s * n + c0, L) = d.A.middleCols(ps * n + c0, L);
      else
        d.A.middleCols(s * n + c0, L).setZero();
      continue;
    }
    const int r0 = J.idx_v, L = d.block_end[b] - r0;
    if (J.nv == 1) {
      const ArticulatedBody& A = ws.articulated[b];
      auto x = X.col(r0).segment(r0, L);
      x *= 1 / A.d;
      const Vec6 K = A.U / A.d;
      if (ps >= 0) x.noalias() -= d.A.middleCols(ps * n + r0, L).transpose() * K;
      if (s < 0) continue;
      if (ps >= 0) {
        if (s != ps) d.A.middleCols(s * n + r0, L) = d.A.middleCols(ps * n + r0, L);
        d.A.middleCols(s * n + r0, L).noalias() += A.S * x.transpose();
      } else {
        d.A.middleCols(s * n + r0, L).noalias() = A.S * x.transpose();
      }
      continue;
    }
    auto u = d.rows.topLeftCorner(L, J.nv);
    u = X.block(r0, r0, L, J.nv);
    for (int k = 0; k < J.nv; ++k) {
      const ArticulatedRate& R = ws.articulated_rate[r0 + k];
      auto x = X.col(r0 + k).segment(r0, L);
      x.noalias() = u * R.Dinv.head(J.nv);
      if (ps >= 0) x.noalias() -= d.A.middleCols(ps * n + r0, L).transpose() * R.K;
    }
    if (s < 0) continue;
    auto As = d.A.middleCols(s * n + r0, L);
    if (ps >= 0) {
      if (s != ps) As = d.A.middleCols(ps * n + r0, L);
    } else {
      As.setZero();
    }
    for (int k = 0; k < J.nv; ++k)
      As.noalias() += ws.subspace[r0 + k] * X.col(r0 + k).segment(r0, L).transpose();
  }
  for (int b = 0; b < nb; ++b) {  // the upper triangle from the lower; outside the blocks 0
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    const int first = d.block_first[b], end = d.block_end[b];
    for (int c = J.idx_v; c < J.idx_v + J.nv; ++c) {
      X.col(c).head(first).setZero();
      X.col(c).tail(n - end).setZero();
      for (int r = first; r < c; ++r) X(r, c) = X(c, r);
    }
  }
}

// Y ← sign (M^s)⁻¹ Y by the articulated factorisation (articulated_solve's steps) on eight
// columns at a time: O(bodies) per column, as the column solves, with the per-body work shared.
void solve_chunks(const Model& m, const Workspace& ws, DerivativeWorkspace& d, MatX& Y,
                  double sign) {
  using Row8 = Eigen::Matrix<double, 1, 8>;
  const int nb = static_cast<int>(m.bodies.size());
  for (Eigen::Index c0 = 0; c0 < Y.cols(); c0 += 8) {
    const Eigen::Index w = std::min<Eigen::Index>(8, Y.cols() - c0);
    if (w < 8) d.chunk.setZero();
    d.chunk.leftCols(w) = sign * Y.middleCols(c0, w);
    for (int b = nb - 1; b >= 0; --b) {  // leaves to root: u = f − Sᵀ p, p += U D⁻¹ u
      const Body& body = m.bodies[b];
      const Joint& J = body.joint;
      auto& p = d.chunk_force[b];
      if (J.nv == 1) {
        const ArticulatedBody& A = ws.articulated[b];
        auto x = d.chunk.row(J.idx_v);
        x.noalias() -= A.S.transpose() * p;
        p.noalias() += (A.U / A.d) * x;
      } else if (J.nv > 1) {
        for (int k = 0; k < J.nv; ++k)
          d.chunk.row(J.idx_v + k).noalias() -= ws.subspace[J.idx_v + k].transpose() * p;
        for (int k = 0; k < J.nv; ++k)
          p.noalias() += ws.articulated_rate[J.idx_v + k].K * d.chunk.row(J.idx_v + k);
      }
      if (body.parent >= 0) d.chunk_force[body.parent] += p;
      p.setZero();  // ready for the next chunk
    }
    for (int b = 0; b < nb; ++b) {  // root to leaves: x = D⁻¹ u − D⁻¹ Uᵀ a, a += S x
      const Body& body = m.bodies[b];
      const Joint& J = body.joint;
      auto& a = d.chunk_acceleration[b];
      if (body.parent >= 0)
        a = d.chunk_acceleration[body.parent];
      else
        a.setZero();
      if (J.nv == 1) {
        const ArticulatedBody& A = ws.articulated[b];
        auto x = d.chunk.row(J.idx_v);
        x = (x - A.U.transpose() * a) / A.d;
        a.noalias() += A.S * x;
      } else if (J.nv > 1) {
        Eigen::Matrix<double, 6, 8> u;
        u.topRows(J.nv) = d.chunk.middleRows(J.idx_v, J.nv);
        for (int k = 0; k < J.nv; ++k) {
          const ArticulatedRate& R = ws.articulated_rate[J.idx_v + k];
          Row8 x = R.Dinv.head(J.nv).transpose() * u.topRows(J.nv);
          x.noalias() -= R.K.transpose() * a;
          d.chunk.row(J.idx_v + k) = x;
        }
        for (int k = 0; k < J.nv; ++k)
          a.noalias() += ws.subspace[J.idx_v + k] * d.chunk.row(J.idx_v + k);
      }
    }
    Y.middleCols(c0, w) = d.chunk.leftCols(w);
  }
}

// Y = −(M^s)⁻¹ K by the factorisation forward_dynamics left: the articulated one eight columns at
// a time (the sweep's route), else column by column.
void minus_minv_solve(const Model& m, Workspace& ws, DerivativeWorkspace& d, const MatX& K,
                      MatX& Y) {
  Y = K;
  if (d.minv_sweep)
    solve_chunks(m, ws, d, Y, -1.0);
  else
    solve_columns(m, ws, d, Y, -1.0);
}

// The rows where a column of ∂τ/∂q or ∂τ/∂v of body b's rates can be non-zero: the rates of b's
// ancestors and of b's subtree (a pair (c, m) couples only along one path to the root), as runs
// of consecutive rates, merged. Needs the sweep's depth-first numbering (sub_first, sub_count).
// A two-point spring couples the rates of its two bodies' paths across branches: with springs
// every column is taken whole. Consecutive bodies with the same rows (the bodies of a chain
// segment below its last branching: each one's ancestors and subtree are the segment's whole
// path) form one group of columns. A run is cut where a block of (M^s)⁻¹ ends (with springs).
void plan_row_runs(const Model& m, DerivativeWorkspace& d) {
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  d.groups.clear();
  d.runs.clear();
  std::vector<int> rate_block(n);  // per rate, the body whose block it is in
  for (int b = 0; b < nb; ++b) {
    const Joint& J = m.bodies[b].joint;
    if (moves(J)) std::fill_n(rate_block.begin() + J.idx_v, J.nv, b);
  }
  std::vector<std::pair<int, int>> rows, merged;  // (first, count), root first
  std::vector<RowRun> cut;
  for (int b = 0; b < nb; ++b) {
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    merged.clear();
    if (!m.springs.empty()) {
      merged.emplace_back(0, m.n());
    } else {
      rows.clear();
      rows.emplace_back(d.sub_first[b], d.sub_count[b]);
      for (int a = m.bodies[b].parent; a >= 0; a = m.bodies[a].parent)
        if (moves(m.bodies[a].joint))
          rows.emplace_back(m.bodies[a].joint.idx_v, m.bodies[a].joint.nv);
      std::sort(rows.begin(), rows.end());
      for (const auto& [first, count] : rows)
        if (!merged.empty() && merged.back().first + merged.back().second == first)
          merged.back().second += count;
        else
          merged.emplace_back(first, count);
    }
    cut.clear();
    for (const auto& [first, count] : merged)
      for (int r = first; r < first + count;) {
        const int blk = rate_block[r];
        const int end = std::min(first + count, d.block_end[blk]);
        cut.push_back({r, end - r, d.block_first[blk], d.block_end[blk]});
        r = end;
      }
    const auto same = [](const RowRun& x, const RowRun& y) {
      return x.first == y.first && x.count == y.count;  // (the same rates: the same blocks)
    };
    if (!d.groups.empty()) {
      ColumnGroup& g = d.groups.back();
      if (g.first + g.count == J.idx_v &&
          std::equal(d.runs.begin() + g.run_begin, d.runs.end(), cut.begin(), cut.end(), same)) {
        g.count += J.nv;
        continue;
      }
    }
    const int begin = static_cast<int>(d.runs.size());
    d.runs.insert(d.runs.end(), cut.begin(), cut.end());
    d.groups.push_back({J.idx_v, J.nv, begin, static_cast<int>(d.runs.size())});
  }
}

// Y = −(M^s)⁻¹ K over K's non-zero rows only (plan_row_runs), each run times its block of
// (M^s)⁻¹: per column a few small products.
void minus_minv_times(const DerivativeWorkspace& d, const MatX& K, MatX& Y) {
  for (const ColumnGroup& g : d.groups)
    for (int c = g.first; c < g.first + g.count; ++c) {
      auto y = Y.col(c);
      y.setZero();
      for (int r = g.run_begin; r < g.run_end; ++r) {
        const RowRun& run = d.runs[r];
        const int rows = run.block_end - run.block_first;
        y.segment(run.block_first, rows).noalias() -=
            d.Minv.block(run.block_first, run.first, rows, run.count) *
            K.col(c).segment(run.first, run.count);
      }
    }
}

// Whether the sweep applies (articulated route, every subtree's rates contiguous with the
// joint's own first), and its per-body layout.
void plan_inverse_sweep(const Model& m, DerivativeWorkspace& d) {
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  if (m.dynamics_route != DynamicsRoute::Articulated || !m.identity_coupling) return;
  std::vector<int> lo(nb, n), hi(nb, -1);
  d.sub_count.assign(nb, 0);
  for (int b = nb - 1; b >= 0; --b) {
    const Joint& J = m.bodies[b].joint;
    if (moves(J)) {
      d.sub_count[b] += J.nv;
      lo[b] = std::min(lo[b], J.idx_v);
      hi[b] = std::max(hi[b], J.idx_v + J.nv - 1);
      if (lo[b] != J.idx_v) return;  // a descendant's rate before the joint's own
    }
    if (d.sub_count[b] > 0 && hi[b] - lo[b] + 1 != d.sub_count[b]) return;
    if (const int p = m.bodies[b].parent; p >= 0) {
      if (p >= b) return;
      d.sub_count[p] += d.sub_count[b];
      lo[p] = std::min(lo[p], lo[b]);
      hi[p] = std::max(hi[p], hi[b]);
    }
  }
  d.sub_first = lo;
  // Each body's block of (M^s)⁻¹: the subtree of its topmost moving ancestor-or-self, or its
  // own subtree if none moves (parents come before children here).
  std::vector<int> top(nb);
  d.block_first.assign(nb, 0);
  d.block_end.assign(nb, 0);
  for (int b = 0; b < nb; ++b) {
    const int p = m.bodies[b].parent;
    top[b] = p >= 0 && moves(m.bodies[top[p]].joint) ? top[p] : b;
    d.block_first[b] = d.sub_first[top[b]];
    d.block_end[b] = d.sub_first[top[b]] + d.sub_count[top[b]];
  }
  // The last child of each body with rates below it: it may reuse its parent's slot.
  std::vector<int> last(nb, -1);
  for (int b = 0; b < nb; ++b)
    if (const int p = m.bodies[b].parent; p >= 0 && d.sub_count[b] > 0) last[p] = b;
  d.slot.assign(nb, -1);
  int slots = 0;
  for (int b = 0; b < nb; ++b) {
    const int own = moves(m.bodies[b].joint) ? m.bodies[b].joint.nv : 0;
    if (d.sub_count[b] - own <= 0) continue;  // no rates below: its accelerations are not read
    const int p = m.bodies[b].parent;
    d.slot[b] = p >= 0 && d.slot[p] >= 0 && last[p] == b ? d.slot[p] : slots++;
  }
  plan_row_runs(m, d);
  d.P.setZero(6, n);
  d.A.setZero(6, static_cast<Eigen::Index>(slots) * n);
  d.rows.setZero(n, 6);
  d.chunk_force.assign(nb, Eigen::Matrix<double, 6, 8>::Zero());
  d.chunk_acceleration.assign(nb, Eigen::Matrix<double, 6, 8>::Zero());
  d.chunk.setZero(n, 8);
  d.minv_sweep = true;
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
  plan_inverse_sweep(m, *this);
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
  if (m.identity_coupling) return;
  d.KC.noalias() = Kq * m.C;  // ∂τ_q/∂q = Cᵀ (∂τ_θ/∂θ) C
  d.dtau_dq.noalias() = m.C.transpose() * d.KC;
  d.KC.noalias() = Kv * m.C;
  d.dtau_dv.noalias() = m.C.transpose() * d.KC;
}

}  // namespace

void inverse_dynamics_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d,
                                  const VecX& q, const VecX& qd, const VecX& qdd) {
  if (m.coupling_level) return law_inverse_derivatives(m, ws, d, q, qd, qdd);
  inverse_derivatives(m, ws, d, q, qd, qdd, false);
}

Status forward_dynamics_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d,
                                    const VecX& q, const VecX& qd, const VecX& tau) {
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
  // ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂·: up to n = 96 by products with (M^s)⁻¹ (on the sweep's route over
  // ∂τ's non-zero rows only), above by the factorisation.
  for (const auto& [K, Y] : {std::pair{&d.dtau_dq, &d.dqdd_dq}, std::pair{&d.dtau_dv, &d.dqdd_dv}})
    if (m.n() > kDenseProductSize)
      minus_minv_solve(m, ws, d, *K, *Y);
    else if (d.minv_sweep)
      minus_minv_times(d, *K, *Y);
    else
      Y->noalias() = -d.Minv * *K;
  return st;
}

void inverse_mass_matrix(const Model& m, Workspace& ws, DerivativeWorkspace& d) {
  if (d.minv_sweep) return inverse_mass_sweep(m, ws, d);
  d.Minv.setIdentity();
  solve_columns(m, ws, d, d.Minv, 1.0);
}

void linearization(const Model& m, const DerivativeWorkspace& d, const VecX& qd, MatX& A, MatX& B) {
  const int n = m.n();
  A.setZero(2 * n, 2 * n);
  B.setZero(2 * n, n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = d.dqdd_dq;
  A.bottomRightCorner(n, n) = d.dqdd_dv;
  B.bottomRows(n) = d.Minv;
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (J.type == JointType::Spherical) {  // ξ̇ = J_r(ξ)⁻¹ ω: −½ [ω]×
      A.block<3, 3>(c.v, c.v) = -0.5 * skew(qd.segment<3>(c.v));
    } else if (J.type == JointType::Free) {  // ξ̇_p = exp(ξ_r) v_p: −[v_p]×; ξ̇_r as above
      A.block<3, 3>(c.v, c.v + 3) = -skew(qd.segment<3>(c.v));
      A.block<3, 3>(c.v + 3, c.v + 3) = -0.5 * skew(qd.segment<3>(c.v + 3));
    }
  }
}

}  // namespace femdyn
