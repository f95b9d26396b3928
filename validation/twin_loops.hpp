// The closed loops of the Simbody twin (twin.hpp, TwinModel::closed_loop()): the rods that span
// two bodies as slender rigid bodies, the coupled joints as coordinate couplers, and the state
// that q, q̇ give them. Includes Simbody: compiled like twin.cpp (C++17, without NDEBUG).
//
// A rod between point a of body A and point b of body B, length L, mass m:
//   a body on MobilizedBody::LineOrientation at a (frame F: body A's axes at a; the rod along
//   its z axis, which carries no inertia), mass m at (0, 0, L/2), inertia about its origin
//   diag(mL²/3, mL²/3, 0); Constraint::Ball joins its point (0, 0, L) to b. Its kinetic energy
//   ½ m |v_c|² + ½ (mL²/12) |ω⊥|² with v_c = (v_a + v_b)/2 and |ω⊥| L = |v_b − v_a| is
//   (m/6)(|v_a|² + v_a·v_b + |v_b|²), the rod element's (elements/rod.hpp); gravity acts at
//   the middle, as m/2 at each end.
#pragma once
#include <Simbody.h>

#include <vector>

#include "validation/twin.hpp"

namespace femdyn::validation::loops {

// θ = g(q) and θ̇ = G q̇ by the laws in their dependency order, each by its own chain rule
// θ̇_t = Σ_k ∂f/∂x_k θ̇_{s_k} (the twin's own; femdyn's is core/model/coupling_level.hpp). Throws
// std::runtime_error naming the joint where a law is not defined.
void joint_state(const TwinModel& m, const VecX& q, const VecX& qd, VecX& theta, VecX& theta_dot);

// Each rod as a body on a LineOrientation mobilizer of its body A (after the tree's bodies).
std::vector<SimTK::MobilizedBody> add_rods(const TwinModel& m,
                                           std::vector<SimTK::MobilizedBody>& tree);

// A Constraint::Ball at every rod's far end, and a Constraint::CoordinateCoupler for every law
// whose loop no rod closes: φ(θ_t, θ_s…) = θ_t − f(θ_s…) = 0.
void add_constraints(SimTK::SimbodyMatterSubsystem& matter, const TwinModel& m,
                     std::vector<SimTK::MobilizedBody>& tree,
                     std::vector<SimTK::MobilizedBody>& rods);

// With the tree's q and u already in `state`: each rod's q pointing it from a to b and its u
// the angular velocity that carries b along (ω = d × v_rel / L in A's frame, v_rel the velocity
// of b relative to A). Leaves the state realized to Velocity.
void fit_rods(const SimTK::MultibodySystem& system, SimTK::State& state, const TwinModel& m,
              const std::vector<SimTK::MobilizedBody>& tree,
              const std::vector<SimTK::MobilizedBody>& rods);

}  // namespace femdyn::validation::loops
