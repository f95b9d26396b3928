// Time integration of M^s q̈ + h = Q: classical fixed-step RK4 on (q, q̇), and the quintic
// (minimum-jerk) point-to-point reference used for computed-torque trajectories.
#pragma once
#include <functional>

#include "core/equations.hpp"

namespace femdyn {

// One RK4 step of length dt under the actuation τ(t). Returns a failed Status (and leaves
// q, q̇ unchanged) if M^s is singular on the way.
using Actuation = std::function<void(double t, VecX& tau)>;
Status rk4_step(const Model& model, Workspace& ws, double t, double dt, VecX& q, VecX& qd,
                const Actuation& tau);

// q(t) = q0 + (q1 − q0) s(t/T), s(x) = 10x³ − 15x⁴ + 6x⁵: zero velocity and acceleration at
// both ends. Fills q, q̇, q̈ at time t (clamped to [0, T]).
void quintic(const VecX& q0, const VecX& q1, double T, double t, VecX& q, VecX& qd, VecX& qdd);

}  // namespace femdyn
