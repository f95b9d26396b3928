// The quintic (minimum-jerk) point-to-point reference used for computed-torque trajectories
// (femdyn track). Time integration is in sim/integrator.hpp.
#pragma once
#include "core/math.hpp"

namespace femdyn {

// q(t) = q0 + (q1 − q0) s(t/T), s(x) = 10x³ − 15x⁴ + 6x⁵: zero velocity and acceleration at
// both ends. Fills q, q̇, q̈ at time t (clamped to [0, T]).
void quintic(const VecX& q0, const VecX& q1, double T, double t, VecX& q, VecX& qd, VecX& qdd);

}  // namespace femdyn
