#include "core/loops/constrained_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/dynamics/articulated.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/model/arguments.hpp"

namespace femdyn {

namespace {

// Y = M⁻¹ Φ_qᵀ column by column by `solve` (x ← M⁻¹ x), S = Φ_q Y, and S factorised.
template <class Solve>
void fill_constraint_space(LoopWorkspace& lws, Solve&& solve) {
  for (Eigen::Index i = 0; i < lws.k.J.rows(); ++i) {
    lws.column = lws.k.J.row(i).transpose();
    solve(lws.column);
    lws.Y.col(i) = lws.column;
  }
  lws.S.noalias() = lws.k.J * lws.Y;
  pivoted_cholesky(lws);
}

// q̈₀, Φ, Φ_q, Φ̇_q v, Y and S factorised, on the articulated route (C = I, the body-level form
// exact): q̈₀ by the articulated recursion, Φ_q from the rates' spatial columns it leaves, and
// Y = M⁻¹ Φ_qᵀ by its factorisation, one O(bodies) solve a column: O(n m) in all, no n × n
// matrix, where the Cholesky route costs O(Σ depth²) (a chain: O(n³)).
Status articulated_constraint_space(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                    const VecX& q, const VecX& v, const VecX& tau) {
  // The model's forward dynamics is the articulated recursion here (two-point springs added).
  if (Status st = tree_forward_dynamics(model, ws, q, v, tau); !st.ok) return st;
  lws.qdd0 = ws.qdd;
  propagate(model, ws, q, v, {.jacobian = false, .bias = true, .rows = false});
  constraint_kinematics_by_paths(model, ws, lws.k);
  fill_constraint_space(lws, [&](VecX& x) { articulated_solve(model, ws, x); });
  return {};
}

// The same on every other route: M^s formed and factorised (core/workspace/mass_solver.hpp), q̈₀
// from one inverse dynamics (Q − h = τ − τ_ID(q, v, 0)).
Status cholesky_constraint_space(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                 const VecX& q, const VecX& v, const VecX& tau) {
  inverse_dynamics(model, ws, q, v, lws.zero);  // τ_ID = h − Q(τ = 0)
  lws.tau_id = ws.tau;
  mass_matrix(model, ws, q);
  if (Status st = ws.solver.factorize(ws.Ms); !st.ok) return st;
  lws.qdd0 = -lws.tau_id;
  if (tau.size()) lws.qdd0 += tau;  // (none: no actuation)
  ws.solver.solve_in_place(lws.qdd0);
  constraint_kinematics(model, ws, q, v, lws.k);
  factorize_constraint_space(model, ws, lws);
  return {};
}

}  // namespace

LoopWorkspace::LoopWorkspace(const Model& model)
    : constraint_space(model.dynamics_route == DynamicsRoute::Articulated
                           ? articulated_constraint_space
                           : cholesky_constraint_space),
      k(model),
      zero(VecX::Zero(model.n())),
      tau_id(model.n()),
      qdd0(model.n()),
      column(model.n()),
      Y(model.n(), model.constraint_rows),
      S(model.constraint_rows, model.constraint_rows),
      r(model.constraint_rows),
      lambda(model.constraint_rows),
      Slambda(model.constraint_rows),
      stabilization(model.constraint_rows),
      F(model.constraint_rows, model.constraint_rows),
      y(model.constraint_rows),
      perm(model.constraint_rows) {}

void factorize_constraint_space(const Model&, Workspace& ws, LoopWorkspace& lws) {
  fill_constraint_space(lws, [&](VecX& x) { ws.solver.solve_in_place(x); });
}

// P S Pᵀ = L Lᵀ by Cholesky with diagonal pivoting on the Schur complement (Higham, "Accuracy
// and Stability of Numerical Algorithms" §10.3): at step k the largest remaining diagonal of
// the complement is the pivot, and the factorisation stops where it falls below ε_rank of S's
// largest diagonal: L is m × rank, and rank is S's numerical rank. (Eigen's LDLT picks its
// pivots from S's own diagonal, not the complement's, and is not rank revealing: on Bricard's
// mechanism it put a near-zero pivot inside the factor and λ grew to 1e9.)
void pivoted_cholesky(LoopWorkspace& lws) {
  MatX& F = lws.F;
  F = lws.S;
  const int m = static_cast<int>(F.rows());
  for (int i = 0; i < m; ++i) lws.perm[i] = i;
  const double largest = m ? F.diagonal().maxCoeff() : 0.0;
  lws.rank = 0;
  for (int k = 0; k < m; ++k) {
    Eigen::Index j = 0;
    const double pivot = F.diagonal().tail(m - k).maxCoeff(&j);
    if (!(pivot > kRankTolerance * largest)) break;
    j += k;
    F.row(k).swap(F.row(j));
    F.col(k).swap(F.col(j));
    std::swap(lws.perm[k], lws.perm[j]);
    const double d = std::sqrt(F(k, k));
    F(k, k) = d;
    const int rest = m - k - 1;
    F.col(k).tail(rest) /= d;
    F.bottomRightCorner(rest, rest).noalias() -=
        F.col(k).tail(rest) * F.col(k).tail(rest).transpose();
    ++lws.rank;
  }
}

namespace {
constexpr const char* kDeadPoint = "the constraint Jacobian is singular at this configuration";
}  // namespace

bool at_dead_point(const Status& status) {
  return !status.ok && status.message.find(kDeadPoint) != std::string::npos;
}

Status solve_constraint_space(const Model& model, LoopWorkspace& lws, double allowance) {
  // The basic solution: with P S Pᵀ = [L₁; L₂] [L₁; L₂]ᵀ (L₁ rank × rank), the permuted λ is
  // (L₁⁻ᵀ L₁⁻¹ (P r)₁, 0): the redundant equations' multipliers zero.
  auto& x = lws.lambda;
  const int m = static_cast<int>(x.size()), rank = lws.rank;
  for (int i = 0; i < m; ++i) lws.y[i] = lws.r[lws.perm[i]];
  auto head = lws.y.head(rank);
  const auto L1 = lws.F.topLeftCorner(rank, rank);
  L1.triangularView<Eigen::Lower>().solveInPlace(head);
  L1.triangularView<Eigen::Lower>().transpose().solveInPlace(head);
  lws.y.tail(m - rank).setZero();
  for (int i = 0; i < m; ++i) x[lws.perm[i]] = lws.y[i];
  // No solution: r has a part outside the range of S (Φ_q lost rank where the loops do not
  // allow it: a dead point, or constraints that contradict each other).
  lws.Slambda.noalias() = lws.S * x;
  lws.Slambda -= lws.r;
  Eigen::Index worst = 0;
  const double miss = lws.Slambda.size() ? lws.Slambda.cwiseAbs().maxCoeff(&worst) : 0;
  const double scale =
      lws.r.cwiseAbs().maxCoeff() + lws.S.cwiseAbs().maxCoeff() * x.cwiseAbs().maxCoeff();
  if (!(miss <= kConsistencyTolerance * scale + allowance)) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1e", scale > 0 ? miss / scale : miss);
    return {false,
            std::string(kDeadPoint) +
                " (a dead point, or constraints that contradict each other): constraint '" +
                constraint_row_name(model, static_cast<int>(worst)) +
                "' cannot be held (relative residual " + text + ")",
            -1, !std::isfinite(miss)};
  }
  return {};
}

double loop_size(const Model& model, const Vec3& origin) {
  double size = 1;
  for (const LoopConstraint& c : model.constraints) {
    if (c.type == ConstraintType::Gear) continue;  // (joints, no places)
    for (const Attachment* a : {&c.a, &c.b})
      size = std::max(size, a->body < 0 ? (a->p - origin).norm() : a->p.norm());
  }
  return size;
}

Status closed_state(const Model& model, Workspace& ws, ConstraintKinematics& k, const VecX& q,
                    const VecX& v) {
  constraint_kinematics(model, ws, q, v, k);
  const double size = loop_size(model, ws.origin);
  const VecX rate = k.J * v;
  const double v_max = v.size() ? v.cwiseAbs().maxCoeff() : 0.0;
  const double position_tol = kClosedStateTolerance * size,
               velocity_tol = kClosedStateTolerance * size * std::max(1.0, v_max);
  Eigen::Index row = 0;
  const auto refuse = [&](const char* state, const char* what, double value, double tol) {
    char value_text[32], tol_text[32];
    std::snprintf(value_text, sizeof value_text, "%.3g", value);
    std::snprintf(tol_text, sizeof tol_text, "%.3g", tol);
    return Status{false,
                  std::string(state) + ": " + what + " = " + value_text + " at constraint '" +
                      constraint_row_name(model, static_cast<int>(row)) + "', above " + tol_text +
                      " (the closed mechanism's equations hold only on them: assemble the state "
                      "first, as simulate does)",
                  -1};
  };
  if (k.phi.size() && k.phi.cwiseAbs().maxCoeff(&row) > position_tol)
    return refuse("q does not close the loops", "|Φ(q)|", std::abs(k.phi[row]), position_tol);
  if (rate.size() && rate.cwiseAbs().maxCoeff(&row) > velocity_tol)
    return refuse("q̇ does not keep the loops closed", "|Φ_q q̇|", std::abs(rate[row]), velocity_tol);
  return {};
}

Status mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace* lws,
                                  const VecX& q, const VecX& v, const VecX& tau) {
  return model.routes.mechanism_forward_dynamics(model, ws, lws, q, v, tau);
}

Status tree_mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace*,
                                       const VecX& q, const VecX& v, const VecX& tau) {
  return forward_dynamics(model, ws, q, v, tau);
}

Status closed_mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace* lws,
                                         const VecX& q, const VecX& v, const VecX& tau) {
  require_state(model, "mechanism_forward_dynamics", q, &v);
  if (!lws)
    throw ArgumentError("mechanism_forward_dynamics: the model '" + model.name +
                        "' has closed loops and no LoopWorkspace was given");
  if (Status st = closed_state(model, ws, lws->k, q, v); !st.ok) return st;
  return constrained_forward_dynamics(model, ws, *lws, q, v, tau, 0);
}

Status constrained_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                    const VecX& q, const VecX& v, const VecX& tau, double omega) {
  require_state(model, "constrained_forward_dynamics", q, &v);
  require_size(model, "constrained_forward_dynamics", "tau", tau, ArgumentKind::Actuation);
  if (Status st = lws.constraint_space(model, ws, lws, q, v, tau); !st.ok) return st;
  // r = −(Φ̇_q v + Φ_q q̈₀) − (2ω Φ_q v + ω² Φ), the second part Baumgarte's
  lws.stabilization.noalias() = 2 * omega * lws.k.J * v;
  lws.stabilization += omega * omega * lws.k.phi;
  lws.r.noalias() = -lws.k.J * lws.qdd0;
  lws.r -= lws.k.bias + lws.stabilization;
  const double allowance = lws.stabilization.size() ? lws.stabilization.cwiseAbs().maxCoeff() : 0.0;
  if (Status st = solve_constraint_space(model, lws, allowance); !st.ok) return st;
  ws.qdd = lws.qdd0;
  ws.qdd.noalias() += lws.Y * lws.lambda;
  return finite_accelerations(model, ws.qdd);
}

}  // namespace femdyn
