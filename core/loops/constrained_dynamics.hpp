// Forward dynamics of a mechanism whose loops are closed by constraints (docs/loops.md):
//
//   M^s q̈ + h = Q + Φ_qᵀ λ,     Φ_q q̈ = −Φ̇_q v − 2ω Φ_q v − ω² Φ,
//
// in the spanning tree's coordinates, with Baumgarte's stabilisation at rate ω (critically
// damped: a residual decays as (1 + ωt) e^{−ωt}; ω = 0 leaves Φ̈ = 0 alone). Solved in the range
// space of M^s, with the tree's own factorisation (core/mass_solver.hpp):
//
//   q̈₀ = M⁻¹ (Q − h)          (Q − h = τ − τ_ID(q, v, 0), one inverse dynamics)
//   Y  = M⁻¹ Φ_qᵀ,   S = Φ_q Y  (m solves, m × m)
//   S λ = −(Φ̇_q v + Φ_q q̈₀ + 2ω Φ_q v + ω² Φ),    q̈ = q̈₀ + Y λ.
//
// S is factorised by LDLᵀ with diagonal pivoting (rank revealing on a semidefinite S): pivots
// below ε_rank of the largest are dropped, so that redundant constraints (a planar loop closed
// by 3-D balls, Bricard's mechanism) leave λ's redundant part at zero and q̈ exact, and are
// counted in `rank`. A system with no solution — the constraint Jacobian singular at a dead
// point or a lock-up — is a failed Status naming the constraint, never a NaN.
#pragma once
#include "core/loops/constraint_kinematics.hpp"
#include "core/status.hpp"

namespace femdyn {

struct LoopWorkspace {
  explicit LoopWorkspace(const Model& model);
  ConstraintKinematics k;
  VecX zero, tau_id, qdd0, column;
  MatX Y;  // M⁻¹ Φ_qᵀ (n × m)
  MatX S;  // Φ_q M⁻¹ Φ_qᵀ (m × m)
  Eigen::LDLT<MatX> ldlt;
  VecX r, lambda, Slambda, stabilization;
  int rank = 0;  // of S at the last solve
};

inline constexpr double kRankTolerance = 1e-10;        // ε_rank, relative to S's largest pivot
inline constexpr double kConsistencyTolerance = 1e-6;  // |S λ − r| relative to |r|

// q̈ into ws.qdd and λ into lws.lambda at (q, v, τ); ω the Baumgarte rate (1/s).
Status constrained_forward_dynamics(const Model& model, Workspace& ws, LoopWorkspace& lws,
                                    const VecX& q, const VecX& v, const VecX& tau, double omega);

// After a factorisation of M^s in ws.solver and Φ_q in lws.k.J: Y and S, and S factorised.
// (Shared by the dynamics and the velocity projection.)
void factorize_constraint_space(const Model& model, Workspace& ws, LoopWorkspace& lws);
// λ with S λ = lws.r, dropping the pivots below ε_rank (sets lws.rank); fails when the
// equations have no solution: lws.r outside the range of S by more than kConsistencyTolerance
// of its scale plus `allowance` (the part of r that may be inconsistent: Baumgarte's
// correction, whose components along redundant equations no λ can meet — it is then met in
// the least-squares sense).
Status solve_constraint_space(const Model& model, LoopWorkspace& lws, double allowance);

}  // namespace femdyn
