// A 1-DOF joint's own forces on its coordinate θ (docs/control.md, "Actuators, friction and
// limits"), each present only where the model gives it:
//
//   spring     −k (θ − θ_rest)                            conservative: V = ½ k (θ − θ_rest)²
//   damper     −c θ̇                                       power −c θ̇²
//   Coulomb    −F_c tanh(θ̇ / v_s)                          power −F_c tanh(θ̇ / v_s) θ̇ ≤ 0
//   stop       above the upper limit, x = θ − upper > 0:  min(0, −k_s x (1 + d θ̇))
//              below the lower limit, x = θ − lower < 0:  max(0, −k_s x (1 − d θ̇))
//              (Simbody's Force::MobilityLinearStop: Hunt–Crossley dissipation, zero at first
//              touch, never pulling the joint into the stop). Its elastic part −k_s x is
//              conservative, V = ½ k_s x²; the rest does work (f + k_s x) θ̇.
//
// The regularised Coulomb law is a smooth damper of slope F_c / v_s at θ̇ = 0: that slope, and
// the stop's frequency sqrt(k_s / m_eff), are what limit an explicit integrator's step
// (femdyn check). The rotor's reflected inertia I_a G² is in M^s, not here (core/model/model.hpp).
#pragma once
#include <algorithm>
#include <cmath>

#include "core/model/model.hpp"

namespace femdyn {

inline double coulomb_force(const Joint& j, double theta_dot) {
  return -j.friction * std::tanh(theta_dot / j.friction_velocity);
}

// The stop's force and its elastic part −k_s x (both 0 inside the limits or without a stop).
struct StopForce {
  double force = 0, elastic = 0;
};
// The Coulomb forces on every joint rate at θ̇ (n_θ entries, in θ̇ order): what the MuJoCo peer
// is handed as an applied force (its frictionloss is a constraint, off there). On the
// coordinates they act as Gᵀ f (G = ∂θ/∂q).
inline VecX coulomb_joint_forces(const Model& m, const VecX& theta_dot) {
  VecX f = VecX::Zero(m.n_theta());
  for (const Body& b : m.bodies)
    if (b.joint.friction != 0 && b.joint.nv == 1 && b.joint.idx_v >= 0)
      f[b.joint.idx_v] += coulomb_force(b.joint, theta_dot[b.joint.idx_v]);
  return f;
}

// The same on every coordinate at q̇, for a model without couplings (q̇ = θ̇).
inline VecX coulomb_forces(const Model& m, const VecX& qd) { return coulomb_joint_forces(m, qd); }

inline StopForce stop_force(const Joint& j, double theta, double theta_dot) {
  if (theta > j.upper) {
    const double x = theta - j.upper;
    return {std::min(0.0, -j.stop_stiffness * x * (1 + j.stop_dissipation * theta_dot)),
            -j.stop_stiffness * x};
  }
  if (theta < j.lower) {
    const double x = theta - j.lower;
    return {std::max(0.0, -j.stop_stiffness * x * (1 - j.stop_dissipation * theta_dot)),
            -j.stop_stiffness * x};
  }
  return {};
}

// Spring + damper + Coulomb friction + stop.
inline double passive_joint_force(const Joint& j, double theta, double theta_dot) {
  double f = 0;
  if (j.stiffness != 0) f -= j.stiffness * (theta - j.rest);
  if (j.damping != 0) f -= j.damping * theta_dot;
  if (j.friction != 0) f += coulomb_force(j, theta_dot);
  if (j.stop) f += stop_force(j, theta, theta_dot).force;
  return f;
}

// The potential of the conservative parts: the spring and the stop's elastic part.
inline double passive_joint_potential(const Joint& j, double theta) {
  double V = 0;
  if (j.stiffness != 0) V += 0.5 * j.stiffness * (theta - j.rest) * (theta - j.rest);
  if (j.stop) {
    const double x = theta > j.upper ? theta - j.upper : theta < j.lower ? theta - j.lower : 0.0;
    V += 0.5 * j.stop_stiffness * x * x;
  }
  return V;
}

// The power of the non-conservative parts: damper, Coulomb friction, the stop's dissipation.
inline double passive_joint_power(const Joint& j, double theta, double theta_dot) {
  double P = 0;
  if (j.damping != 0) P -= j.damping * theta_dot * theta_dot;
  if (j.friction != 0) P += coulomb_force(j, theta_dot) * theta_dot;
  if (j.stop) {
    const StopForce s = stop_force(j, theta, theta_dot);
    P += (s.force - s.elastic) * theta_dot;
  }
  return P;
}

// A spherical or free joint's damper: −c on each of its rates (ω, and v of a free joint, in the
// body's axes). Isotropic, so it is the wrench (−c v, −c ω) whatever the axes, as MuJoCo's
// dof_damping in its world-axes ṗ (ṗ = R v: Rᵀ(−c R v) = −c v). Power −c |θ̇_j|².
// y += sign · (−c θ̇) over q̇ (Model::RateDamper::v), rates over q̇.
inline void add_rate_dampers(const Model& m, const VecX& rates, double sign, VecX& y) {
  for (const Model::RateDamper& d : m.rate_dampers)
    y.segment(d.v, d.nv) -= (sign * d.c) * rates.segment(d.v, d.nv);
}

// The flexible bars' damping (Model::rate_damping, compile/bar_damping.hpp): y += sign · (−D q̇).
inline void add_rate_damping(const Model& m, const VecX& qd, double sign, VecX& y) {
  for (int k = 0; k < m.rate_damping.outerSize(); ++k)
    for (SpMat::InnerIterator it(m.rate_damping, k); it; ++it)
      y[it.row()] -= sign * it.value() * qd[it.col()];
}

// Whether the joint dissipates energy (damper, friction or a stop's dissipation).
inline bool dissipates(const Joint& j) {
  return j.damping != 0 || j.friction != 0 || (j.stop && j.stop_dissipation != 0);
}

}  // namespace femdyn
