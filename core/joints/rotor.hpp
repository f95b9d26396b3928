// A joint's rotor (armature I_a behind a gear G: a = I_a G², Joint::reflected_inertia) adds
// ½ a |θ̇_j|² to the kinetic energy for each rate θ̇_j of its joint, as MuJoCo's dof_armature
// does. Its mass a on those rates is in M^s (Model::armature_mass; the articulated route's D).
//
// A velocity term appears only where a joint's rates are quasi-velocities whose ½ a |·|² is not
// left unchanged by the joint's own motion. By the Boltzmann–Hamel equations, for T_a = ½ a (|v|²
// + |ω|²) in B's axes on a free joint (core/joints/free.hpp, v first):
//
//   linear rates:   d/dt(a v) + ω × (a v)               = a v̇ + a ω × v
//   angular rates:  d/dt(a ω) + ω × (a ω) + v × (a v)   = a ω̇
//
// so h gains h_a = a ω × v on the linear rates: the rotor's "mass" moves with B's origin, whose
// world velocity ṗ = R v has |ṗ| = |v|. A ball joint's ω (isotropic a) and a one-coordinate
// joint's θ̇ give none. (MuJoCo's free joint takes the linear rate ṗ in world axes, where the same
// rotor has no velocity term: validate's MuJoCo row compares the two through ṗ = R v.)
#pragma once
#include "core/model/model.hpp"

namespace femdyn {

// y += sign · h_a(rates): rates and y over q̇ (Model::FreeRotor::v) of a model without a coupling
// law. No work: q̇ᵀ h_a = a v·(ω × v) = 0.
inline void add_rotor_bias(const Model& m, const VecX& rates, double sign, VecX& y) {
  for (const Model::FreeRotor& r : m.free_rotors) {
    const Vec3 v = rates.segment<3>(r.v), w = rates.segment<3>(r.v + 3);
    y.segment<3>(r.v) += (sign * r.a) * w.cross(v);
  }
}

// ∂h_a/∂θ̇ added into K (n_θ × n_θ, over θ̇): ∂(ω × v)/∂v = [ω]×, ∂(ω × v)/∂ω = −[v]×.
template <class Mat>
void add_rotor_bias_rate_derivative(const Model& m, const VecX& theta_dot, Mat& K) {
  for (const Model::FreeRotor& r : m.free_rotors) {
    const Vec3 v = theta_dot.segment<3>(r.theta), w = theta_dot.segment<3>(r.theta + 3);
    K.template block<3, 3>(r.theta, r.theta) += r.a * skew(w);
    K.template block<3, 3>(r.theta, r.theta + 3) -= r.a * skew(v);
  }
}

// h_a as the tensor of h = D[q̇, q̇]: D_k(3 + i, j) += a ε_kij over the free joints' rates of q̇.
inline void add_rotor_bias_tensor(const Model& m, std::vector<MatX>& D) {
  for (const Model::FreeRotor& r : m.free_rotors)
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;  // (ω × v)_k = ω_i v_j − ω_j v_i
      D[r.v + k](r.v + 3 + i, r.v + j) += r.a;
      D[r.v + k](r.v + 3 + j, r.v + i) -= r.a;
    }
}

}  // namespace femdyn
