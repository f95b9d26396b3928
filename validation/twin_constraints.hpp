// The model's loop constraints and two-point springs in the Simbody twin (twin.hpp), compiled
// like twin.cpp. femdyn's constraints (core/model/loop_constraint.hpp) as Simbody's:
//   ball                    Constraint::Ball (A's point on B's)
//   ball in a plane (n),    Constraint::PointOnLine: A's point on the line through B's point
//   point on line           along n (the line's direction), fixed in B
//   point on plane          Constraint::PointInPlane: A's point in B's plane through its point
//   weld                    Constraint::Weld (the frames coincide)
//   distance                Constraint::Rod
//   gear                    Constraint::CoordinateCoupler with a Function::Linear
// each disabled by default (the pointwise rows compare the tree); springs as
// Force::TwoPointLinearSpring and Force::TwoPointLinearDamper (always on).
#pragma once
#include <Simbody.h>

#include <vector>

#include "validation/twin.hpp"

namespace femdyn::validation::constraints {

void add_springs(SimTK::GeneralForceSubsystem& forces, SimTK::SimbodyMatterSubsystem& matter,
                 const TwinModel& m, std::vector<SimTK::MobilizedBody>& tree);

// One Simbody constraint per TwinModel::constraints, in order, disabled by default.
std::vector<SimTK::Constraint> add_constraints(SimTK::SimbodyMatterSubsystem& matter,
                                               const TwinModel& m,
                                               std::vector<SimTK::MobilizedBody>& tree);

}  // namespace femdyn::validation::constraints
