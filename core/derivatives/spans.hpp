// The terms of the analytic derivatives (core/derivatives/derivatives.hpp) of the elements that
// span bodies (ElementEntry::spans: a node on another body, as the rod coupler of a four-bar). Such
// an element uses only its nodes' translations x_l (world axes) with a constant mass m_e (blocks
// M_lj), so by Lagrange with T = ½ Σ_lj ẋ_lᵀ M_lj ẋ_j it adds to τ forces at its nodes,
//   τ_c += Σ_l J_c(x_l)ᵀ F_l,   F_l = Σ_j M_lj (ẍ_j − g)   (its gravity M g, as in F_constant),
// and so, with the point formulas of core/derivatives/points.hpp,
//   ∂τ_c/∂θ_m = Σ_l [J_c(x_l) turning at F_l fixed] + Σ_l J_c(x_l)ᵀ Σ_j M_lj ∂ẍ_j/∂θ_m,
//   ∂τ_c/∂θ̇_m = Σ_l J_c(x_l)ᵀ Σ_j M_lj ∂ẍ_j/∂θ̇_m.
// The body-level recursion covers every other element (Model::condensable_off_spans).
#pragma once
#include <string>
#include <vector>

#include "core/derivatives/points.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct DerivativeWorkspace;

// The spanning elements' masses and buffers, sized once (size_for).
struct SpanDerivatives {
  std::vector<int> elements;  // indices into Model::elements
  std::vector<MatX> mass;     // per element: m_e on its nodes' translations (3k × 3k)
  std::vector<PointMotion> node;
  std::vector<std::vector<int>> path;   // per node: the rates on its body's path
  std::vector<int> rates;               // their union
  std::vector<unsigned char> listed;    // per rate: in `rates` (while an element is formed)
  std::vector<Vec3> arm;                // per rate: add_point_turning's scratch
  VecX x_ddot, force;                   // the nodes' ẍ − g, and F (3k)
  MatX dxdd_dq, dxdd_dv, dF_dq, dF_dv;  // 3k × nθ: ∂ẍ/∂θ, ∂ẍ/∂θ̇, and M times them
  void size_for(const Model& model);
};

// "" if every spanning element of `model` is of that kind (translations only, no velocity
// force), else why not.
std::string span_derivatives_unsupported(const Model& model);

// Adds the spanning elements' ∂τ/∂θ to Kq and ∂τ/∂θ̇ to Kv (joint level), at the body poses in ws
// and the recursion's S, V, V̄, a, ā in d.
void add_span_derivatives(const Model& model, const Workspace& ws, DerivativeWorkspace& d, MatX& Kq,
                          MatX& Kv);

}  // namespace femdyn
