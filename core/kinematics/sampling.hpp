// Seeded random states for studies and validation: q uniform within each coordinate's joint
// limits (±π rad for a revolute joint without limits, ±0.5 m for a prismatic one).
#pragma once
#include <random>

#include "core/model/model.hpp"

namespace femdyn {

VecX random_posture(const Model& model, std::mt19937& rng);
// Each coordinate at 0, or at its joint's nearest limit when 0 is outside them.
VecX reference_posture(const Model& model);
VecX random_uniform(int n, double scale, std::mt19937& rng);
// Rates uniform in ±scale (the draws of random_uniform(n, scale)), those of a joint whose model
// narrows its random range (Joint::sample_range: a flexible bar's strains) narrowed alike.
VecX random_rates(const Model& model, double scale, std::mt19937& rng);
// Every joint at its neutral configuration: its "initial" value (0 unless the model gives one),
// the identity rotation. q of size n_q.
VecX neutral_posture(const Model& model);
// q ⊕ ξ over the coordinate joints (ξ of size n, in each joint's chart around its q).
VecX integrate_posture(const Model& model, const VecX& q, const VecX& xi);
// ξ̇ = the chart rates at (q ⊕ ξ) for the rates v, joint by joint (v when flat).
VecX chart_rates(const Model& model, const VecX& q, const VecX& xi, const VecX& v);
// ∂ξ̇/∂ξ at ξ = 0 for the rates v (n × n): each joint's own block (chart_rate_jacobian), 0 when
// flat. The top-left block of every linearisation A = ∂(ξ̇, v̇)/∂(ξ, v).
MatX chart_rate_jacobian(const Model& model, const VecX& v);
// Whether every joint is flat (q holds one entry per rate, q ⊕ ξ = q + ξ).
bool flat_model(const Model& model);
// Each quaternion in q normalised (one already unit to within 4 ε left as it is: normalising
// twice changes no bit); "" if each had norm 1 within 1e-6, else the first that did not
// ("quaternion of joint 'base' has norm 0.5, expected 1").
std::string normalize_quaternions(const Model& model, VecX& q);  // each entry in ±scale

}  // namespace femdyn
