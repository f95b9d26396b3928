// The two-point springs' terms of the analytic derivatives (core/derivatives/derivatives.hpp; the
// springs are core/dynamics/springs.hpp). A spring pulls its end A by f = −s ê, s = k (ℓ − ℓ₀) + c
// ℓ̇, with d = x_A − x_B, ℓ = |d|, ê = d / ℓ, u = ẋ_A − ẋ_B, ℓ̇ = êᵀ u, and B by −f. On the joint
// rates
//   Q_c = Δ_cᵀ f,   Δ_c = J_c(x_A) − J_c(x_B) = ∂d/∂θ_c,
// J_c(x) the velocity at x of the rate's column (0 off x's path), and τ_θ gains −Q. Along the
// tangent θ ⊕ ε e_m (θ̇ fixed), with g_m = êᵀ Δ_m = ∂ℓ/∂θ_m:
//   ∂Q_c/∂θ_m = Δ_cᵀ ∂f/∂θ_m + (the turning of J_c(x_A), J_c(x_B) at ±f fixed),
//   ∂f/∂θ_m  = −(k g_m + c ∂ℓ̇/∂θ_m) ê − (s / ℓ) (Δ_m − ê g_m),
//   ∂ℓ̇/∂θ_m = (Δ_m − ê g_m)ᵀ u / ℓ + êᵀ ∂u/∂θ_m,
// with the turning and ∂ẋ/∂θ_m of core/derivatives/points.hpp. Along θ̇_m: ∂ℓ̇/∂θ̇_m = g_m, so
// ∂Q_c/∂θ̇_m = −c g_c g_m. O(path²) per spring.
#pragma once
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct DerivativeWorkspace;

// The springs' buffers, per rate of θ̇ (sized once by size_for; nothing per call).
struct SpringDerivatives {
  std::vector<Vec3> delta, du_dq;          // Δ_r = ∂d/∂θ_r, ∂u/∂θ_r
  std::vector<Vec3> arm;                   // one end's J_r(x) × f, for its geometric pairs
  std::vector<double> dl, dl_dot;          // ∂ℓ/∂θ_r = g_r, ∂ℓ̇/∂θ_r
  std::vector<int> path_a, path_b, rates;  // each end's rates (deepest first), their union
  std::vector<unsigned char> on_a;         // per rate: on A's path (while a spring is formed)
  void size_for(const Model& model);
};

// Adds the springs' −∂Q/∂θ to Kq and −∂Q/∂θ̇ to Kv (the joint-level nθ × nθ matrices, before the
// coupling map), at the body poses in ws and the columns S, velocities V, V̄ and θ̇ in d (those
// of the derivative recursion at the same state).
void add_spring_derivatives(const Model& model, const Workspace& ws, DerivativeWorkspace& d,
                            MatX& Kq, MatX& Kv);

}  // namespace femdyn
