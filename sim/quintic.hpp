// The quintic (minimum-jerk) point-to-point reference used for computed-torque trajectories
// (femdyn track). Time integration is in sim/integrator.hpp.
#pragma once
#include "core/model/model.hpp"
#include "core/spatial/math.hpp"

namespace femdyn {

// q(t) = q0 ⊕ s(t/T) Δ joint by joint, s(x) = 10x³ − 15x⁴ + 6x⁵: zero velocity and
// acceleration at both ends; Δ = q1 ⊖ q0 (n entries, `configuration_difference`), so on flat
// joints q(t) = q0 + (q1 − q0) s, and a ball's rotation follows the geodesic. Fills q (n_q
// entries), v and v̇ (n; by the kernel's ray_rates) at time t, clamped to [0, T].
void quintic(const Model& m, const VecX& q0, const VecX& delta, double T, double t, VecX& q,
             VecX& v, VecX& vdot);
// Δ = q1 ⊖ q0 over the coordinate joints (n entries).
VecX configuration_difference(const Model& m, const VecX& q0, const VecX& q1);

}  // namespace femdyn
