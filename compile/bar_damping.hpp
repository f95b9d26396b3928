// The flexible bars' mass-proportional and modal damping (docs/flexible.md, "Damping"): a
// constant matrix D on each bar's elastic rates e, built from the bar's mass and stiffness at
// rest, the rest of the mechanism held in its neutral posture:
//   M̄ = M^s(q0)[e, e],  K = diag(k) (the bar's springs),  K φ_k = ω_k² M̄ φ_k,  Φᵀ M̄ Φ = I,
//   D = α M̄ + M̄ Φ diag(2 ζ_k ω_k) Φᵀ M̄,
// so that each clamped mode k has the damping ratio ζ_k (+ α/(2 ω_k), + β ω_k/2 from the
// stiffness-proportional dampers beside the springs). Q −= D q̇ (Model::rate_damping).
#pragma once
#include <vector>

#include "compile/spec.hpp"
#include "core/model/model.hpp"

namespace femdyn {

// Fills m.rate_damping from the bars that ask for it; a finished model (its routes chosen: M^s
// is evaluated). Refused, naming the bar's damping, on a model with a coupling law, or where a
// bar's joint is coupled to another coordinate.
void compile_bar_damping(const std::vector<BarSpec>& bars, Model& m);

}  // namespace femdyn
