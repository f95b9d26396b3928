// The analytic derivatives (core/derivatives/derivatives.hpp) of a model with a nonlinear coupling
// level θ = g(q) (core/model/coupling_level.hpp), chained from those of its tree (Model::tree,
// every joint a coordinate) as its equations are (core/dynamics/coupling_chain.hpp):
//   τ_q(q, q̇, q̈) = Gᵀ τ_θ(θ, θ̇, θ̈),   θ = g(q),   θ̇ = G q̇,   θ̈ = G q̈ + γ,   γ = g''[q̇, q̇].
// With the tree's K_q = ∂τ_θ/∂θ, K_v = ∂τ_θ/∂θ̇ (the recursion) and M_θ = ∂τ_θ/∂θ̈ (its mass
// matrix), and the nθ × n rows Θ = ∂θ̇/∂q, Ā = ∂(G q̈)/∂q, Γ = ∂γ/∂q:
//   ∂τ_q/∂q = W + Gᵀ (K_q G + K_v Θ + M_θ (Ā + Γ)),   W = Σ_t τ_θ,t H_t   (H_t = ∂²θ_t/∂q²)
//   ∂τ_q/∂v = Gᵀ (K_v G + 2 M_θ Θ)                   (∂γ/∂q̇ = 2 Θ: γ_t = q̇ᵀ H_t q̇)
// The rows chain forward through the laws in dependency order, as G and γ do: for a joint t
// following s_1 … s_k by f, with f_k, f_kl, f_klp its derivatives (a coordinate's rows are e_a
// and zeros),
//   Θ_t = Σ_k f_k Θ_sk + Σ_kl f_kl θ̇_sk G_sl,        Ā_t = Σ_k f_k Ā_sk + Σ_kl f_kl (G q̈)_sk G_sl,
//   Γ_t = Σ_k f_k Γ_sk + Σ_kl f_kl (γ_sk G_sl + Θ_sk θ̇_sl + θ̇_sk Θ_sl)
//         + Σ_klp f_klp θ̇_sk θ̇_sl G_sp,
// and W backward (reverse accumulation of H_t = Σ_k f_k H_sk + Σ_kl f_kl G_skᵀ G_sl): weights
// w = τ_θ, then for t last to first W += w_t Σ_kl f_kl G_skᵀ G_sl, w_sk += f_k w_t.
// Forward dynamics q̈ = (Gᵀ M_θ G)⁻¹ (…): ∂q̈/∂· = −(M^s)⁻¹ ∂τ_q/∂·|_q̈ by the Cholesky factor
// of M^s = Gᵀ M_θ G that the law chain's forward dynamics leaves (Workspace::reduced).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/spatial/math.hpp"
#include "core/workspace/status.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct DerivativeWorkspace;

// The chain's buffers, sized once for a model with a coupling level.
struct LawDerivatives {
  explicit LawDerivatives(const Model& model);  // throws ModelError if the tree is not covered
  ~LawDerivatives();
  LawDerivatives(const LawDerivatives&) = delete;
  LawDerivatives& operator=(const LawDerivatives&) = delete;

  std::unique_ptr<DerivativeWorkspace> tree;  // the tree's K_q, K_v
  MatX G, Theta, A_bar, Gamma;  // nθ × n: G, ∂θ̇/∂q, ∂(G q̈)/∂q, ∂γ/∂q
  VecX theta;                   // θ = g(q) (n_θq)
  VecX theta_dot, Gqdd, gamma, theta_ddot, weight;  // θ̇, G q̈, γ, θ̈, W's weights w (nθ)
  MatX W;                                           // Σ_t τ_θ,t H_t (n × n)
  MatX inner, MX;                  // nθ × n: the bracket of ∂τ_q/∂·, and Ā + Γ
  std::vector<int> df_at, d2f_at;  // per coupled joint: where its f_k, f_kl are in df, d2f
  std::vector<double> df, d2f;     // every law's f_k and f_kl (kept for W's backward pass)
  std::vector<double> x, d3f;      // one law's arguments and f_klp
};

// "" if the chain covers `model` (a model with Model::coupling_level): its tree's coverage.
std::string law_derivatives_unsupported(const Model& model);

// ∂τ/∂q, ∂τ/∂v at (q, v, q̈) into d.dtau_dq, d.dtau_dv. Throws StateError where a law is not
// defined (as inverse_dynamics does).
void law_inverse_derivatives(const Model& model, Workspace& ws, DerivativeWorkspace& d,
                             const VecX& q, const VecX& qd, const VecX& qdd);

// q̈ (into ws.qdd and d.qdd), ∂q̈/∂q, ∂q̈/∂v and (M^s)⁻¹ into d; a failed forward dynamics as is.
Status law_forward_derivatives(const Model& model, Workspace& ws, DerivativeWorkspace& d,
                               const VecX& q, const VecX& qd, const VecX& tau);

}  // namespace femdyn
