// The work-precision study (femdyn study, docs/simulation.md): every femdyn integrator over a
// sweep of steps or tolerances and every Simbody integrator over a sweep of accuracies, each
// run's error against a reference solution and its wall time.
//
//   error(run) = max over the sample times t_k (t_0 = 0 included) and the groups g of
//                max_{j∈g} |(x_run(t_k) ⊖ x_ref(t_k))_j| / S_g,
//   S_g = max over the samples of max_{j∈g} |(x_ref(t_k) ⊖ x_0)_j|,
// a dimensionless relative state error: x = (θ, θ̇), the joint coordinates (θ = C q + θ0, or the
// coupling laws' θ = g(q)) and rates, so both engines are measured alike. ⊖ is the difference on
// each joint's manifold, one component per rate: θ − θ_ref on a flat joint, the rotation vector
// log(R_refᵀ R) of a ball's or free joint's quaternion (so q and −q are one), and θ̇ − θ̇_ref;
// x_0 is the neutral configuration at rest. The groups are the angles (rad), the angular rates
// (rad/s), and the translations (m) and speeds (m/s) of prismatic, planar and free joints, so no
// error is divided by a size of another unit. The absolute errors (the
// largest |Δθ| and |Δθ̇|) are kept beside it. The reference is Dormand–Prince landing on each
// sample at rtol 1e-14, its own error estimated by the same measure against the run at rtol
// 1e-13 (an upper estimate). A run whose error is below 100x that estimate is "unresolved" and
// kept out of plots and tables.
//
// Sampling: with `interpolate` (the default) both engines step freely and interpolate at the
// samples (femdyn's dopri and bdf by their dense output, Simbody's integrators by
// Integrator::stepTo without a scheduled event, TwinSampling::Interpolate); without, both land
// on every sample (femdyn's stop_at_outputs; Simbody's TimeStepper). femdyn's fixed-step rk4 and
// euler land on the samples either way: their steps T/(samples·2^k) divide the sample spacing.
//
// Timing: femdyn's time is the integrator's set-up and its advance_to calls, Simbody's its
// integrator's initialize and stepTo calls (neither counts sampling or energies). Sweeps advance
// round-robin with femdyn and Simbody alternating; each run of a sweep is a warm-up whose time is
// not kept (it sets the error, the steps and whether the sweep goes on), then every run is timed
// again `repeats` times (`long_repeats` if the warm-up took `repeat_below` or longer), in rounds
// that alternate the engines again, and the median is kept.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/model/model.hpp"

namespace femdyn::validation {

struct StudyOptions {
  double t_end = 1.0;
  int samples = 20;            // sample times t_end·k/samples, k = 1..samples
  VecX q0, qd0;                // initial state (sizes n_q and n)
  bool interpolate = true;     // both engines interpolate at the samples, or both land on them
  int repeats = 5;             // timed runs after the warm-up, for a run under repeat_below
  int long_repeats = 3;        // timed runs after the warm-up, for a longer run
  double repeat_below = 0.05;  // s
  double run_budget = 2.0;     // s: a sweep stops tightening after a run this long
  bool quick = false;          // fewer sweep points, tighter budgets, 3 repeats (CI smoke)
  // s: a reference run still going past it is stopped and the study fails (0: no limit). The
  // caller refuses beforehand what estimate_study puts beyond it.
  double budget = 0;
  // Told the reference runs' progress, at most every 20 ms: which run ("reference (rtol
  // 1e-14)"), and the model time it has reached.
  std::function<void(const std::string& run, double t)> reference_progress;
  // s: the warm-up runs are stopped past it (a failed run that ends its sweep): 4x the
  // run budget (0.2 s with quick).
  double run_limit() const { return 4 * (quick ? 0.2 : run_budget); }
};

// The study's cost up front. The sweeps are bounded by their rules (each ends at its first run
// over run_budget, a warm-up is stopped at run_limit(), its repeats are of runs that ended
// below it); the reference is not, and is estimated by a probe: the reference method (dopri at
// rtol 1e-14, landing on the samples) run from the start for up to kProbeSeconds of wall time
// or to t_end, its pace extrapolated to t_end, for the two reference runs (rtol 1e-14 and 1e-13:
// 10^(1/5) fewer steps, a fifth-order method's).
struct StudyEstimate {
  static constexpr double kProbeSeconds = 0.5;
  double probe_t = 0;     // s of model time the probe reached
  double probe_wall = 0;  // s of wall time it took
  double reference = 0;   // s: both reference runs, extrapolated
};
StudyEstimate estimate_study(const Model& model, const StudyOptions& options);

struct StudyRun {
  std::string engine;      // "femdyn" or "Simbody"
  std::string integrator;  // "rk4", "euler", "dopri", "bdf", or Simbody's class name
  std::string setting;     // "dt", "rtol" or "accuracy"
  double value = 0;
  double error = 0;           // the relative state error (dimensionless; see above)
  double position_error = 0;  // max |θ − θ_ref| over the samples: rad (m for prismatic joints)
  double rate_error = 0;      // max |θ̇ − θ̇_ref|: rad/s (m/s)
  double final_error = 0;     // the relative state error at t_end alone
  double energy_drift = 0;    // max |E(t_k) − E(0)| (J); meaningful for conservative models
  double wall_time = 0;       // median of the timed runs (s)
  double warm_up_time = 0;    // the warm-up run's time, not in the median (s)
  std::vector<double> times;  // every timed run's wall time
  long steps = 0, rhs_evals = 0;
  bool ok = true;
  std::string failure;
  bool resolved = true;  // error ≥ 100x the reference's estimated error
};

// What the timings were taken on: the CPU, the cores and the load average (/proc/loadavg, over
// 1, 5 and 15 minutes) when the study started and when it ended.
struct StudyMachine {
  std::string cpu = "unknown CPU";  // /proc/cpuinfo "model name"
  int cores = 0;                    // std::thread::hardware_concurrency()
  std::vector<double> load_start, load_end;
};
StudyMachine study_machine();        // cpu and cores
std::vector<double> load_average();  // /proc/loadavg's three averages, or empty

struct StudyReport {
  std::string model;
  int n = 0;
  double t_end = 0;
  int samples = 0;
  VecX q0, qd0;
  bool conservative = true;
  bool interpolate = true;
  std::string sampling;  // one sentence: how each engine reaches the sample times
  // The sizes S_g the errors are divided by, each with its unit: {"angle", S, "rad"}, …
  struct Scale {
    std::string quantity;
    double size = 0;
    std::string unit;
  };
  std::vector<Scale> scales;
  std::string reference_method;
  double reference_rtol = 0, reference_error = 0;  // the estimate
  double resolution = 0;                           // 100x reference_error
  double reference_wall = 0;  // s: both reference runs' wall time (StudyEstimate::reference's)
  // Whether both engines integrate the same equations: false where the Simbody twin is a
  // constrained system (a closed loop, or linear coordinate couplers) while femdyn integrates
  // the reduced coordinates; then `formulation` says how each does it.
  bool same_formulation = true;
  std::string femdyn_formulation, simbody_formulation;
  int timed_repeats = 0, timed_repeats_long = 0;  // as run (quick: 3 and 3)
  std::vector<StudyRun> runs;
  std::vector<std::string> notes;
  StudyMachine machine;
};

// Throws std::runtime_error if the reference itself cannot be computed. `log` hears one line
// per run.
StudyReport run_study(const Model& model, const StudyOptions& options,
                      const std::function<void(const std::string&)>& log = {});

// The fastest resolved run of `engine` whose error is ≤ target, or nullptr.
const StudyRun* fastest(const StudyReport& report, const std::string& engine, double target);

}  // namespace femdyn::validation
