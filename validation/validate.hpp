// femdyn against its Simbody twin: pointwise at seeded random states, and along a passive
// trajectory. docs/validation.md describes the method and the tolerance policy.
#pragma once
#include <string>
#include <vector>

#include "core/model.hpp"
#include "validation/twin.hpp"

namespace femdyn::validation {

// The longest trajectory compared (s), for `femdyn validate --t-end` and femdyn.validate's
// t_end alike: a bound on the check's run time. femdyn's RK4 run starts at a 1 ms step
// (rk4_step) and is refined only within a budget of max_rk4_steps (1e5) steps, which a
// trajectory of 100 s spends at its first halving.
inline constexpr double kMaxTrajectoryTime = 100;

struct ValidationOptions {
  int states = 20;  // K seeded random states
  unsigned seed = 1;
  double qd_scale = 2;               // q̇ uniform in ±qd_scale (rad/s, m/s)
  double tau_scale = 1;              // τ uniform in ±tau_scale (N·m, N)
  double qdd_scale = 5;              // q̈ for inverse dynamics, uniform in ±qdd_scale
  double tolerance = 1e-10;          // relative, on M^s, h, Q, q̈, τ
  double t_end = 0.25;               // trajectory length (s); 0 = no trajectory
  int samples = 50;                  // trajectory samples compared
  double rk4_step = 1e-3;            // femdyn's first RK4 step (s), halved until the error estimate
  double rk4_target = 1e-9;          // (relative to the state's size) is below this,
  double max_rk4_steps = 1e5;        // or the finer run would take more steps than this
  double resolved_tolerance = 1e-6;  // the trajectory check fails as unresolved above this
  double simbody_accuracy = 1e-10;
};

// One compared quantity: max over the states of ‖x_femdyn − x_simbody‖∞ and of that divided by
// ‖x_simbody‖∞ (the absolute error when the Simbody quantity is zero).
struct QuantityError {
  std::string name;  // "M", "h", "Q", "qdd", "tau"
  double max_abs = 0, max_rel = 0, tolerance = 0;
  bool pass() const { return max_rel <= tolerance; }
};

struct TrajectoryReport {
  bool run = false;
  std::string skipped;  // why not run, if not
  double t_end = 0;
  double max_state_error = 0;  // max over samples of ‖(θ, θ̇)_femdyn − (θ, θ̇)_simbody‖∞
  double rk4_step = 0;         // step of the femdyn run compared
  double rk4_error_estimate = 0;      // Richardson estimate of femdyn's own RK4 error (dt vs dt/2)
  double simbody_error_estimate = 0;  // Simbody at its accuracy against 100x tighter
  bool resolved = true;               // both estimates small enough for the comparison to mean much
  double tolerance = 0;
  double energy_change_femdyn = 0, energy_change_simbody = 0;  // max |E(t) − E(0)|
  std::vector<double> t, error;                                // the state error over time
  std::vector<double> energy_femdyn,
      energy_simbody;  // E(t) of both runs (J; each with its own zero)
  bool pass() const { return !run || (resolved && max_state_error <= tolerance); }
};

struct ValidationReport {
  std::string model;
  int n = 0, states = 0;
  std::vector<QuantityError> quantities;
  TrajectoryReport trajectory;
  std::vector<std::string> notes;  // e.g. approximations the model makes on purpose
  std::string failure;             // why no comparison could be made (then it fails)
  bool pass() const;
};

ValidationReport validate(const Model& model, const ValidationOptions& options = {});

// For a model read from a URDF file: femdyn's M^s, h, Q against an independent Simbody model
// built straight from the XML (urdf_twin.hpp), at the same seeded states. Returns the quantity
// "import" (the largest of the three relative errors); `failure` is set if the twin cannot be
// built.
QuantityError validate_urdf_import(const Model& model, const std::string& urdf_path,
                                   const ValidationOptions& options, std::string& failure);

// What the Simbody twin reads of a model; each body's mass properties are the sum of its
// elements'. Used by validate() and femdyn_bench.
TwinModel twin_model(const Model& model);

}  // namespace femdyn::validation
