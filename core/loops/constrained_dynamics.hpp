// Forward dynamics of a mechanism whose loops are closed by constraints (docs/loops.md):
//
//   M^s q̈ + h = Q + Φ_qᵀ λ,     Φ_q q̈ = −Φ̇_q v − 2ω Φ_q v − ω² Φ,
//
// in the spanning tree's coordinates, with Baumgarte's stabilisation at rate ω (critically
// damped: a residual decays as (1 + ωt) e^{−ωt}; ω = 0 leaves Φ̈ = 0 alone). Solved in the range
// space of M^s, with the tree's own factorisation (core/workspace/mass_solver.hpp):
//
//   q̈₀ = M⁻¹ (Q − h)          (Q − h = τ − τ_ID(q, v, 0), one inverse dynamics)
//   Y  = M⁻¹ Φ_qᵀ,   S = Φ_q Y  (m solves, m × m)
//   S λ = −(Φ̇_q v + Φ_q q̈₀ + 2ω Φ_q v + ω² Φ),    q̈ = q̈₀ + Y λ.
//
// On the articulated route (C = I, the body-level form exact) M^s is never formed: q̈₀ comes from
// the articulated recursion, Φ_q from the rates' spatial columns it leaves, and each column of Y
// from its factorisation (articulated_solve, O(bodies)), so a model with few loops costs O(n m)
// plus the m × m system; on the other routes M^s is formed and factorised (the tree's LTDL).
//
// S is factorised by Cholesky with diagonal pivoting on the Schur complement (rank revealing on
// a semidefinite S): it stops at pivots below ε_rank of the largest diagonal, so that redundant
// constraints (a planar loop closed by 3-D balls, Bricard's mechanism) leave λ's redundant part
// at zero and q̈ exact, and are counted in `rank`. A system with no solution — the constraint
// Jacobian singular at a dead point or a lock-up — is a failed Status naming the constraint, never
// a NaN.
#pragma once
#include <vector>

#include "core/loops/constraint_kinematics.hpp"
#include "core/workspace/status.hpp"

namespace femdyn {

struct LoopWorkspace;

// q̈₀ = M⁻¹ (Q − h), Φ, Φ_q, Φ̇_q v, Y and S factorised at (q, v, τ): the model's route for the
// solver's first half (constrained_dynamics.cpp), chosen once from Model::dynamics_route.
using ConstraintSpaceRoute = Status (*)(const Model&, Workspace&, LoopWorkspace&, const VecX& q,
                                        const VecX& v, const VecX& tau);

struct LoopWorkspace {
  explicit LoopWorkspace(const Model& model);
  ConstraintSpaceRoute constraint_space;
  ConstraintKinematics k;
  VecX zero, tau_id, qdd0, column;
  MatX Y;  // M⁻¹ Φ_qᵀ (n × m)
  MatX S;  // Φ_q M⁻¹ Φ_qᵀ (m × m)
  VecX r, lambda, Slambda, stabilization;
  MatX F;                 // S's pivoted Cholesky factor (pivoted_cholesky)
  VecX y;                 // the permuted right-hand side
  std::vector<int> perm;  // P: position i of the factor holds row perm[i] of S
  int rank = 0;           // of S at the last solve
};

// Baumgarte's rate the simulator uses unless told (1/s): a residual decays in about 1/ω = 50 ms.
inline constexpr double kDefaultBaumgarte = 20;
inline constexpr double kRankTolerance = 1e-10;        // ε_rank, relative to S's largest pivot
inline constexpr double kConsistencyTolerance = 1e-3;  // |S λ − r| relative to its scale

// q̈ into ws.qdd and λ into lws.lambda at (q, v, τ); ω the Baumgarte rate (1/s).
Status constrained_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                    const VecX& q, const VecX& v, const VecX& tau, double omega);

// q̈ of the mechanism the model describes, at a state as given — the answer of every door that
// takes one state (`femdyn equations`, the Python module's equations and forward dynamics, single
// and batch): the tree's forward_dynamics without loops; with loops, the constrained equations
// at ω = 0 (Φ̈ = 0, λ into lws->lambda), after closed_state has found the state on them. `lws`
// may be null only on a model without constraints.
Status mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace* lws,
                                  const VecX& q, const VecX& v, const VecX& tau);
// Its two routes (EquationRoutes::mechanism_forward_dynamics, chosen at compile): the tree's
// forward_dynamics, and the constrained q̈ at ω = 0 from the closed state.
Status tree_mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace* lws,
                                       const VecX& q, const VecX& v, const VecX& tau);
Status closed_mechanism_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace* lws,
                                         const VecX& q, const VecX& v, const VecX& tau);

// L, the size of the loops: the largest distance of a constraint's place (gears have none) from
// its body's origin, or, on the world, from the reference point `origin` (Workspace::origin of
// the last propagate), and at least 1 m. The scale of Φ's round-off (assemble, closed_state).
double loop_size(const Model& model, const Vec3& origin);

// Whether (q, v) is a state of the closed mechanism: |Φ(q)|∞ ≤ kClosedStateTolerance L and
// |Φ_q v|∞ ≤ kClosedStateTolerance L max(1, |v|∞), L ≥ 1 m the size of the constraints' places
// (assembly's); else a failure naming the constraint row and the residual, and the way onto the
// loops. Leaves Φ and Φ_q in k.
inline constexpr double kClosedStateTolerance = 1e-6;
Status closed_state(const Model& model, Workspace& ws, ConstraintKinematics& k, const VecX& q,
                    const VecX& v);

// S's pivoted Cholesky factor into lws.F, lws.perm, lws.rank.
void pivoted_cholesky(LoopWorkspace& lws);
// After a factorisation of M^s in ws.solver and Φ_q in lws.k.J: Y and S, and S factorised.
// (Shared by the dynamics and the velocity projection.)
void factorize_constraint_space(const Model& model, Workspace& ws, LoopWorkspace& lws);
// λ with S λ = lws.r, dropping the pivots below ε_rank (sets lws.rank); fails when the
// equations have no solution: lws.r outside the range of S by more than kConsistencyTolerance
// of its scale plus `allowance` (the part of r that may be inconsistent: Baumgarte's
// correction, whose components along redundant equations no λ can meet — it is then met in
// the least-squares sense).
Status solve_constraint_space(const Model& model, LoopWorkspace& lws, double allowance);
// Whether a failure is solve_constraint_space's (a dead point), however its message is prefixed.
bool at_dead_point(const Status& status);

}  // namespace femdyn
