// Loop constraints and two-point springs in the Simbody validation (validate.hpp): what the twin
// reads of them, and the constrained rows compared at consistent random states.
#pragma once
#include <random>
#include <string>
#include <vector>

#include "core/model/model.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {

// The model's constraints and springs into the twin (TwinConstraint, TwinSpring); a body's
// frame is its mobilized body's in the twin, so attachments carry over as they are.
void add_constraints_and_springs(const Model& m, TwinModel& t);

// The constrained rows: at `states` seeded states (q, q̇ assembled by femdyn's assemble_state,
// so Φ = 0 and Φ_q q̇ = 0), femdyn's constrained_forward_dynamics with ω = 0 against Simbody's
// (SimbodyTwin::loop_dynamics): q̈ into `qdd`, the generalized constraint forces Φ_qᵀ λ into
// `force`, and Simbody's closure errors at femdyn's assembled states into `closure` (relative to
// the mechanism's size, and its speed). States femdyn cannot assemble are skipped with a note
// (none assembled: `failure`).
struct LoopRows {
  QuantityError qdd, force, closure;
  std::vector<std::string> notes;
  std::string failure;
};
LoopRows compare_loops(const Model& m, SimbodyTwin& twin, const ValidationOptions& o,
                       double tolerance);

// An assembled (q, q̇) from a guess drawn from `rng`: the model's neutral posture moved by a
// random step of about 0.3 rad in all (0.3/√n a coordinate: a long chain of loops stays in the
// assembly mode it was described in, rather than folding some loops over, near their dead
// points), then, if that does not assemble, a random posture; q̇ in ±qd_scale, projected onto
// Φ_q q̇ = 0 (assemble_state). False, with `why`, where neither assembles. (The constrained rows
// here, and femdyn bench's and femdyn_bench's constrained timings.)
bool assembled_state(const Model& m, std::mt19937& rng, double qd_scale, VecX& q, VecX& qd,
                     std::string& why);

// A consistent start for the constrained trajectory: (q0, q̇0) assembled, or the model's neutral
// posture (its joints' "initial" values) with q̇0 assembled, whichever keeps Φ_q farther from a
// dead point; false, with `why`, where neither assembles.
bool consistent_state(const Model& m, VecX& q0, VecX& qd0, std::string& why);

}  // namespace femdyn::validation
