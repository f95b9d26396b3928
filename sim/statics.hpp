// Statics: the configuration q at which the mechanism rests under its loads,
//   r(q) = λ τ − τ_id(q, 0, 0) = 0,      τ_id(q, 0, 0) = −Q(q)  (springs, gravity, loads),
// (with closed loops r(q) + Φ_qᵀ μ = 0 and Φ(q) = 0, for q and the constraint forces μ),
// by Newton's method with the analytic stiffness ∂τ_id/∂q (core/derivatives; where it is
// singular, a Levenberg–Marquardt step (K + μ 1) Δ = r, μ the largest |K| or force), a step halved
// until the residual falls, and continuation in the load: λ scales the applied τ, gravity and
// the loads (the model's and `loads` given here) from 0 to 1, in steps that halve where Newton
// does not converge and double where it does. The springs are not scaled. Each step compiles
// the spec at its λ: the model a user loads is the one solved.
#pragma once
#include <vector>

#include "compile/spec.hpp"
#include "core/model/model.hpp"
#include "core/workspace/status.hpp"

namespace femdyn {

struct StaticsOptions {
  VecX tau;                     // applied joint forces (n entries, or empty: 0), scaled by λ
  std::vector<LoadSpec> loads;  // loads added to the model's (body frame point, world force)
  VecX q0;                      // the start (n_q entries, or empty: the neutral configuration)
  double tolerance = 1e-10;     // |r|∞ ≤ tolerance × the largest force met (see StaticsResult)
  int max_iterations = 30;      // Newton steps per load step
  double min_step = 1e-6;       // the smallest load step before the solve gives up
};

struct StaticsResult {
  Status status;        // a failure says at which λ and why
  VecX q;               // the last converged configuration (λ = lambda)
  double lambda = 0;    // the load factor reached (1 when status.ok)
  double residual = 0;  // |r|∞ at q, N or N m (with loops: |r + Φ_qᵀ μ|∞)
  // Closed loops: the constraint forces μ (M^s q̈ + h = Q + Φ_qᵀ μ, core/loops/) and |Φ|∞ at q.
  VecX multipliers;
  double constraint_residual = 0;
  double scale = 0;    // the largest |τ_id|∞ or |λ τ|∞ met: the residual's yardstick
  int load_steps = 0;  // converged load steps
  int iterations = 0;  // Newton steps in all
};

// A model with closed loops starts from q0 assembled onto them and solves the balance with the
// constraint forces, r(q) + Φ_qᵀ μ = 0 on Φ(q) = 0 (sim/statics.cpp, newton_loops).
StaticsResult solve_statics(const MechanismSpec& spec, const StaticsOptions& options);

}  // namespace femdyn
