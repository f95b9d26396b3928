// The work-precision study (femdyn study, docs/simulation.md): every femdyn integrator over a
// sweep of steps or tolerances and every Simbody integrator over a sweep of accuracies, each
// run's error against a reference solution and its wall time.
//
//   error(run) = max over the sample times t_k of ‖x_run(t_k) − x_ref(t_k)‖∞,
//   x = (θ, θ̇): the joint coordinates (θ = C q + θ0) and rates, so both engines are measured
//   alike; the reference is Dormand–Prince landing on each sample at rtol 1e-14, its own error
//   estimated by the difference to the same run at rtol 1e-13 (an upper estimate). A run whose
//   error is below 100x that estimate is "unresolved" and kept out of plots and tables.
//
// Timing: femdyn's time is the integrator's set-up and its advance_to calls, Simbody's its
// TimeStepper's initialize and stepTo calls (neither counts sampling or energies). Sweeps advance
// round-robin with femdyn and Simbody alternating; runs shorter than `repeat_below` are repeated up
// to `repeats` times, in rounds that alternate the engines again, and the median is kept.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/model.hpp"

namespace femdyn::validation {

struct StudyOptions {
  double t_end = 1.0;
  int samples = 20;            // sample times t_end·k/samples, k = 1..samples
  VecX q0, qd0;                // initial state (sizes n)
  int repeats = 5;             // at most, for short runs
  double repeat_below = 0.05;  // s
  double run_budget = 2.0;     // s: a sweep stops tightening after a run this long
  bool quick = false;          // fewer sweep points, tighter budgets (CI smoke)
};

struct StudyRun {
  std::string engine;      // "femdyn" or "Simbody"
  std::string integrator;  // "rk4", "euler", "dopri", "bdf", or Simbody's class name
  std::string setting;     // "dt", "rtol" or "accuracy"
  double value = 0;
  double error = 0;           // max over the samples of ‖x − x_ref‖∞
  double final_error = 0;     // at t_end
  double energy_drift = 0;    // max |E(t_k) − E(0)| (J); meaningful for conservative models
  double wall_time = 0;       // median over the repeats (s)
  std::vector<double> times;  // every repeat's wall time
  long steps = 0, rhs_evals = 0;
  bool ok = true;
  std::string failure;
  bool resolved = true;  // error ≥ 100x the reference's estimated error
};

struct StudyReport {
  std::string model;
  int n = 0;
  double t_end = 0;
  VecX q0, qd0;
  bool conservative = true;
  std::string reference_method;
  double reference_rtol = 0, reference_error = 0;  // the estimate
  double resolution = 0;                           // 100x reference_error
  std::vector<StudyRun> runs;
  std::vector<std::string> notes;
};

// Throws std::runtime_error if the reference itself cannot be computed. `log` hears one line
// per run.
StudyReport run_study(const Model& model, const StudyOptions& options,
                      const std::function<void(const std::string&)>& log = {});

// The fastest resolved run of `engine` whose error is ≤ target, or nullptr.
const StudyRun* fastest(const StudyReport& report, const std::string& engine, double target);

}  // namespace femdyn::validation
