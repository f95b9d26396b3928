// A recommended fixed step tried on the model's own motion (femdyn check, docs/stability.md):
// the linear rules (sim/stability.hpp) judge a step at sampled states, but the motion may move
// faster than those states (a mechanism falling from rest gathers speed) or come nearer a stiff
// posture. So the step is also run: from (q0, q̇0) over a horizon of a few periods of the fastest
// motion, the fixed-step method at dt against Dormand–Prince at rtol = atol = 1e-10, compared
// at 20 evenly spaced times. The error is max_k ‖x_k − x_ref,k‖∞ / max(1, max_k ‖x_ref,k‖∞), x =
// (q, q̇), and per period e / (horizon / period). While the run fails (diverges) or its error per
// period exceeds `allowed`, dt is halved, within a budget of fixed steps.
#pragma once
#include <string>

#include "sim/integrator.hpp"

namespace femdyn {

struct StepTrialOptions {
  double period = 0;           // of the fastest motion (s); the horizon is `periods` of it
  double periods = 3;          // (at most 10 s)
  double horizon = 0;          // s, the run's own length when given (then `periods` is unused)
  double allowed = 0;          // error per period the step must keep
  long step_budget = 200'000;  // fixed steps over all the tries
  int max_halvings = 10;
};

struct StepTrial {
  bool verified = false;          // a step met `allowed` within the budget
  double dt = 0;                  // the step tried last (the verified one when verified)
  int halvings = 0;               // times dt was halved from the one asked
  double horizon = 0;             // s
  double error_per_period = 0;    // measured at dt (NaN where the run failed)
  double error = 0;               // over the whole horizon, relative (NaN where the run failed)
  std::string failure;            // why not verified ("" when verified)
  bool reference_failed = false;  // the motion itself could not be followed (a dead point)
};

StepTrial try_fixed_step(const Model& model, IntegratorKind kind, double dt, const VecX& q0,
                         const VecX& qd0, const StepTrialOptions& options);

}  // namespace femdyn
