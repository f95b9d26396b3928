#include "core/derivatives/loops.hpp"

#include "core/derivatives/derivatives.hpp"

namespace femdyn {

LoopDerivatives::LoopDerivatives(const Model& m)
    : lws(m),
      terms(m),
      R(MatX::Zero(m.n(), m.n())),
      Xq(MatX::Zero(m.n(), m.n())),
      Xv(MatX::Zero(m.n(), m.n())),
      Lq(MatX::Zero(m.constraint_rows, m.n())),
      Lv(MatX::Zero(m.constraint_rows, m.n())),
      Lt(MatX::Zero(m.constraint_rows, m.n())),
      y(VecX::Zero(m.constraint_rows)) {}

namespace {

// Λ ← S⁺ Λ column by column: the basic solution of solve_constraint_space on S's kept pivots
// (P S Pᵀ = L Lᵀ, L₁ rank × rank), the redundant part zero.
void solve_constraint_columns(const LoopWorkspace& lws, VecX& y, MatX& L) {
  const int m = static_cast<int>(L.rows()), rank = lws.rank;
  const auto L1 = lws.F.topLeftCorner(rank, rank);
  for (Eigen::Index k = 0; k < L.cols(); ++k) {
    for (int i = 0; i < m; ++i) y[i] = L(lws.perm[i], k);
    auto head = y.head(rank);
    L1.triangularView<Eigen::Lower>().solveInPlace(head);
    L1.triangularView<Eigen::Lower>().transpose().solveInPlace(head);
    y.tail(m - rank).setZero();
    for (int i = 0; i < m; ++i) L(lws.perm[i], k) = y[i];
  }
}

// ∂q̈ = X + Y Λ with S Λ = −C − Φ_q X (X = M⁻¹ r₁ in place; C the constraint side, or none).
void add_constraint_response(const LoopWorkspace& lws, const MatX* C, VecX& y, MatX& L, MatX& X) {
  L.noalias() = -lws.k.J * X;
  if (C) L -= *C;
  solve_constraint_columns(lws, y, L);
  X.noalias() += lws.Y * L;
}

}  // namespace

Status constrained_forward_dynamics_derivatives(const Model& m, Workspace& ws, LoopWorkspace& lws,
                                                DerivativeWorkspace& d, const VecX& q,
                                                const VecX& v, const VecX& tau, double omega) {
  if (Status st = constrained_forward_dynamics(m, ws, lws, q, v, tau, omega); !st.ok) return st;
  LoopDerivatives& L = *d.loops;
  d.qdd = ws.qdd;
  // ∂τ_ID/∂q, ∂τ_ID/∂v at the constrained q̈ (the body poses in ws at q; the factorisation of
  // M kept), and the recursion's V, a, S in d for the constraints' terms
  inverse_dynamics_derivatives(m, ws, d, q, v, d.qdd);
  constraint_derivatives(m, ws, d, lws.lambda, omega, L.terms);
  inverse_mass_matrix(m, ws, d);  // the tree's M⁻¹ into d.Minv
  L.R = L.terms.G - d.dtau_dq;    // r₁ along q: ∂g/∂q − ∂τ_ID/∂q
  L.Xq.noalias() = d.Minv * L.R;
  L.R = -d.dtau_dv;  // r₁ along v
  L.Xv.noalias() = d.Minv * L.R;
  add_constraint_response(lws, &L.terms.Cq, L.y, L.Lq, L.Xq);
  add_constraint_response(lws, &L.terms.Cv, L.y, L.Lv, L.Xv);
  add_constraint_response(lws, nullptr, L.y, L.Lt, d.Minv);
  d.dqdd_dq = L.Xq;
  d.dqdd_dv = L.Xv;
  return {};
}

}  // namespace femdyn
