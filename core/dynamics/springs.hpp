// The forces of the two-point springs (Model::springs, core/model/two_point_spring.hpp).
#pragma once
#include "core/spatial/math.hpp"

namespace femdyn {

struct Model;
struct Workspace;

// Q_s = Σ (Jv_A − Jv_B)ᵀ f_A at (q, v) into ws.Q_springs (one propagate with Jacobians), and
// the dampers' power −Σ c l̇² into ws.spring_power.
void spring_forces(const Model& model, Workspace& ws, const VecX& q, const VecX& v);
// Σ ½ k (l − l₀)² at q.
double spring_potential(const Model& model, Workspace& ws, const VecX& q);

}  // namespace femdyn
