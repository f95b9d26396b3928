// Analytic derivatives of the constrained forward dynamics (closed loops, docs/loops.md):
//
//   M q̈ + h − Q = τ + Φ_qᵀ λ,     Φ_q q̈ + Φ̇_q v + 2ω Φ_q v + ω² Φ = 0,
//
// differentiated at the solution (q̈, λ), along the tangent convention of
// core/derivatives/derivatives.hpp. With τ_ID(q, v, q̈) the inverse dynamics, g(q) = Φ_qᵀ λ at λ
// fixed and c(q, v) = Φ_q q̈ + Φ̇_q v + 2ω Φ_q v + ω² Φ at q̈ fixed
// (core/derivatives/constraint_derivatives.hpp):
//
//   M dq̈ − Φ_qᵀ dλ = dτ − ∂τ_ID/∂x dx + ∂g/∂x dx,     Φ_q dq̈ = −∂c/∂x dx,
//
// solved in the range space the constrained dynamics leaves (Y = M⁻¹ Φ_qᵀ, S = Φ_q Y by pivoted
// Cholesky): with r₁ the first right side,
//
//   S dλ = −∂c/∂x dx − Φ_q M⁻¹ r₁,     dq̈ = M⁻¹ r₁ + Y dλ,
//
// dλ's redundant part zero as solve_constraint_space leaves λ's (Y maps it to nothing). So
//   ∂q̈/∂q = X_q + Y Λ_q,   X_q = M⁻¹ (∂g/∂q − ∂τ_ID/∂q),   S Λ_q = −C_q − Φ_q X_q,
//   ∂q̈/∂v = X_v + Y Λ_v,   X_v = −M⁻¹ ∂τ_ID/∂v,             S Λ_v = −C_v − Φ_q X_v,
//   ∂q̈/∂τ = M⁻¹ − Y S⁺ Yᵀ   (the projected inverse: zero on Φ_qᵀ's range, S⁺ the basic
//                            solution's inverse on the kept pivots).
// Needs C = I (no coupled joints).
#pragma once
#include "core/derivatives/constraint_derivatives.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/workspace/status.hpp"

namespace femdyn {

struct DerivativeWorkspace;

// The buffers of the constrained derivatives, sized once for a model.
struct LoopDerivatives {
  explicit LoopDerivatives(const Model& model);
  LoopWorkspace lws;  // forward_dynamics_derivatives' own constrained solve
  ConstraintDerivatives terms;
  MatX R, Xq, Xv;   // r₁ per column, and M⁻¹ r₁ along q and along v (n × n)
  MatX Lq, Lv, Lt;  // Λ_q, Λ_v, Λ_τ (m × n)
  VecX y;           // a permuted column of S's system (m)
};

// q̈ (into ws.qdd and d.qdd) of the constrained equations at Baumgarte's rate ω, then ∂q̈/∂q,
// ∂q̈/∂v and ∂q̈/∂τ = M⁻¹ − Y S⁺ Yᵀ (into d.Minv). A failed constrained solve (a dead point)
// is returned as is.
Status constrained_forward_dynamics_derivatives(const Model& model, Workspace& ws,
                                                LoopWorkspace& lws, DerivativeWorkspace& d,
                                                const VecX& q, const VecX& v, const VecX& tau,
                                                double omega);

}  // namespace femdyn
