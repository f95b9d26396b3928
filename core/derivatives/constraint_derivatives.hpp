// The constraints' terms of the derivatives of the constrained forward dynamics
// (core/derivatives/loops.hpp), for each constraint form of core/model/loop_constraint.hpp, along
// the tangent convention of core/derivatives/derivatives.hpp (columns over the rates v; C = I):
//
//   G  = ∂(Φ_qᵀ λ)/∂q at λ fixed                                     (n × n)
//   C_q = ∂c/∂q,  C_v = ∂c/∂v at q̈ fixed,  c = Φ_q q̈ + Φ̇_q v + 2ω Φ_q v + ω² Φ   (m × n)
//
// c is Φ̈ + 2ω Φ̇ + ω² Φ written in the motion of the two places: with d = x_A − x_B, ḋ, d̈ (the
// places' true accelerations at q̈) and for a row along g = R_B e (ġ = ω_B × g):
//   ball       Φ = d,         Φ̇ = ḋ,                       Φ̈ = d̈
//   along g    Φ = gᵀ d,      Φ̇ = gᵀ ḋ + (ω_B × g)ᵀ d,
//              Φ̈ = gᵀ d̈ + 2 (ω_B × g)ᵀ ḋ + (α_B × g + ω_B × (ω_B × g))ᵀ d
//   weld       Φ = R_B log(R_Bᵀ R_A),   Φ̇ = ω_A − ω_B,     Φ̈ = α_A − α_B
//   distance   Φ = |d| − L,   Φ̇ = êᵀ ḋ,                    Φ̈ = êᵀ d̈ + (|ḋ|² − (êᵀ ḋ)²) / |d|
//   gear       Φ, Φ_q constant rows on θ: C_q = ω² Φ_q, C_v = 2ω Φ_q, G = 0.
// Each is differentiated by the product rule from the variations of the places' motion along
// q_k (core/derivatives/points.hpp): δx = J_k(x), the axes turn by δθ = ω_k (δg = ω_k × g),
// δẋ, δẍ, δω, δα from the body's ∂V, ∂a; and along v_k: δx = 0, δg = 0, δẋ = J_k(x), δω = ω_k,
// δẍ, δα from ∂a/∂θ̇_k. The weld's rotation vector φ = R_B log(R_Bᵀ R_A) in world axes varies as
//   δφ = J_l⁻¹(φ) (δθ_A − δθ_B) − φ × δθ_B      (J_l⁻¹(φ) = J_r⁻¹(−φ)).
//
// G is Σ_rows λ_r ∂(row r of Φ_q)/∂q: the rows are point forces and torques at the places,
//   ball       λᵀ (J(x_A) − J(x_B))
//   along g    λ gᵀ (J(x_A) − J(x_B)) + λ (g × d)ᵀ Jω_B
//   weld       (the ball's) + λ_ωᵀ (Jω_A − Jω_B)
//   distance   λ êᵀ (J(x_A) − J(x_B)),
// so G is the turning of the point and angular Jacobians at those forces held fixed
// (add_point_turning, add_axis_turning) plus the turning of the forces themselves:
//   along g    G(c, k) += δf_kᵀ Δ_c + (δf_k × d + f × Δ_k)ᵀ ω_B,c,   Δ = J(x_A) − J(x_B),
//              f = Σ_i λ_i g_i the constraint's force, δf_k = ω_B,k × f
//   distance   G(c, k) += λ (δê_k)ᵀ Δ_c,   δê_k = (Δ_k − ê êᵀ Δ_k) / |d|.
#pragma once
#include <vector>

#include "core/model/attachment.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct DerivativeWorkspace;
using Mat3X = Eigen::Matrix<double, 3, Eigen::Dynamic>;

// One place of a constraint: its pose and motion, and their variations per rate (3 × n, zero
// off the place's path).
struct PlaceDerivatives {
  int body = -1;
  Mat3 R = Mat3::Identity();
  Vec3 x = Vec3::Zero(), x_dot = Vec3::Zero(), x_ddot = Vec3::Zero();  // ẍ the true one
  Vec3 w = Vec3::Zero(), alpha = Vec3::Zero();
  Mat3X dx, turn;                     // along q: δx = J(x), δθ = Jω (also ẋ, ω along v)
  Mat3X dx_dot, dw, dx_ddot, dalpha;  // along q
  Mat3X dx_ddot_v, dalpha_v;          // along v
  std::vector<int> path;              // the rates on its body's path, deepest first
};

struct ConstraintDerivatives {
  explicit ConstraintDerivatives(const Model& model);
  MatX G;       // ∂(Φ_qᵀ λ)/∂q (n × n)
  MatX Cq, Cv;  // ∂c/∂q, ∂c/∂v (m × n)
  PlaceDerivatives A, B;
  std::vector<int> rates;             // the rates on A's or B's path: the columns not zero
  std::vector<unsigned char> marked;  // per rate (scratch of `rates`)
  std::vector<Vec3> arm;              // scratch of add_point_turning (per rate)
};

// G, C_q, C_v at the state of the last derivative recursion in d (its V, a at the constrained
// q̈, its columns S) and the body poses in ws, for the multipliers λ and Baumgarte's rate ω.
void constraint_derivatives(const Model& model, const Workspace& ws, const DerivativeWorkspace& d,
                            const VecX& lambda, double omega, ConstraintDerivatives& out);

}  // namespace femdyn
