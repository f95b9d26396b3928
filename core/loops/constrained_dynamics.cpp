#include "core/loops/constrained_dynamics.hpp"

#include <cstdio>

#include "core/equations.hpp"

namespace femdyn {

LoopWorkspace::LoopWorkspace(const Model& model)
    : k(model),
      zero(VecX::Zero(model.n())),
      tau_id(model.n()),
      qdd0(model.n()),
      column(model.n()),
      Y(model.n(), model.constraint_rows),
      S(model.constraint_rows, model.constraint_rows),
      ldlt(model.constraint_rows),
      r(model.constraint_rows),
      lambda(model.constraint_rows),
      Slambda(model.constraint_rows),
      stabilization(model.constraint_rows) {}

void factorize_constraint_space(const Model& model, Workspace& ws, LoopWorkspace& lws) {
  for (int i = 0; i < model.constraint_rows; ++i) {
    lws.column = lws.k.J.row(i).transpose();
    ws.solver.solve_in_place(lws.column);
    lws.Y.col(i) = lws.column;
  }
  lws.S.noalias() = lws.k.J * lws.Y;
  lws.ldlt.compute(lws.S);
}

Status solve_constraint_space(const Model& model, LoopWorkspace& lws, double allowance) {
  // P S Pᵀ = L D Lᵀ: λ = Pᵀ L⁻ᵀ D⁺ L⁻¹ P r, D⁺ dropping pivots below ε_rank of the largest.
  auto& x = lws.lambda;
  x = lws.ldlt.transpositionsP() * lws.r;
  lws.ldlt.matrixL().solveInPlace(x);
  const auto D = lws.ldlt.vectorD();
  const double largest = D.size() ? D.cwiseAbs().maxCoeff() : 0;
  lws.rank = 0;
  for (Eigen::Index i = 0; i < D.size(); ++i) {
    if (std::abs(D[i]) > kRankTolerance * largest) {
      x[i] /= D[i];
      ++lws.rank;
    } else {
      x[i] = 0;
    }
  }
  lws.ldlt.matrixU().solveInPlace(x);
  x = lws.ldlt.transpositionsP().transpose() * x;
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
            "the constraint Jacobian is singular at this configuration (a dead point, or "
            "constraints that contradict each other): constraint '" +
                constraint_row_name(model, static_cast<int>(worst)) +
                "' cannot be held (relative residual " + text + ")",
            -1, !std::isfinite(miss)};
  }
  return {};
}

Status constrained_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                    const VecX& q, const VecX& v, const VecX& tau, double omega) {
  inverse_dynamics(model, ws, q, v, lws.zero);  // τ_ID = h − Q(τ = 0)
  lws.tau_id = ws.tau;
  mass_matrix(model, ws, q);
  if (Status st = ws.solver.factorize(ws.Ms); !st.ok) return st;
  lws.qdd0 = tau - lws.tau_id;
  ws.solver.solve_in_place(lws.qdd0);
  constraint_kinematics(model, ws, q, v, lws.k);
  factorize_constraint_space(model, ws, lws);
  // r = −(Φ̇_q v + Φ_q q̈₀) − (2ω Φ_q v + ω² Φ), the second part Baumgarte's
  lws.stabilization.noalias() = 2 * omega * lws.k.J * v;
  lws.stabilization += omega * omega * lws.k.phi;
  lws.r.noalias() = -lws.k.J * lws.qdd0;
  lws.r -= lws.k.bias + lws.stabilization;
  const double allowance = lws.stabilization.size() ? lws.stabilization.cwiseAbs().maxCoeff() : 0.0;
  if (Status st = solve_constraint_space(model, lws, allowance); !st.ok) return st;
  ws.qdd = lws.qdd0;
  ws.qdd.noalias() += lws.Y * lws.lambda;
  for (Eigen::Index a = 0; a < ws.qdd.size(); ++a)
    if (!std::isfinite(ws.qdd[a]))
      return {false,
              "q̈ of '" + model.coordinate_names[a] +
                  "' is NaN or Inf (the forces or the state overflow double precision)",
              static_cast<int>(a), true};
  return {};
}

}  // namespace femdyn
