// The validator's trajectory: femdyn's RK4 and Simbody's Runge–Kutta–Merson from one state,
// each run twice (femdyn at dt and dt/2, Simbody at its accuracy and 100x tighter) so that both
// errors are estimated, femdyn's step halved until its error is below the target, and the runs
// compared sample by sample (docs/validation.md, "The trajectory").
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/model/errors.hpp"
#include "sim/fixed_step.hpp"
#include "sim/stability.hpp"
#include "validation/validate_loops.hpp"
#include "validation/validator.hpp"

namespace femdyn::validation {
namespace {

// q and −q are one rotation: each quaternion of x (a joint state θ, θ̇) takes the sign nearer
// ref's (Simbody keeps the sign it starts with, femdyn's integrators keep w ≥ 0).
void align_quaternions(const Model& m, const VecX& ref, VecX& x) {
  for (const Body& b : m.bodies) {
    const Joint& j = b.joint;
    if (!moves(j) || is_flat(j)) continue;
    const int at = j.idx_q + j.nq - 4;  // the quaternion is last
    if (ref.segment<4>(at).dot(x.segment<4>(at)) < 0) x.segment<4>(at) *= -1;
  }
}

// femdyn's passive motion by RK4 (sim/fixed_step.hpp) at step dt, sampled at `times`
// (multiples of dt): the joint states (θ, θ̇) and the states (q, q̇) at the samples.
// Returns false if the integration failed (M^s singular on the way). An overflow along the
// trajectory (NaN or Inf) is an error, never a skipped comparison.
struct Run {
  std::vector<VecX> x, q, qd;
  std::string failure;  // why the integration failed, if it did
  double wall_time = 0;
};
bool integrate(const Model& m, Workspace& ws, const VecX& q0, const VecX& qd0,
               const std::vector<double>& times, double dt, Run& run,
               const std::function<void(double)>& on_sample) {
  const auto t0 = Clock::now();
  run = Run();
  Rk4 rk4(m, {.dt = dt});
  rk4.reset(0, q0, qd0);
  for (double target : times) {
    const Status st = rk4.advance_to(target);
    if (st.non_finite) throw femdyn::Error("along the trajectory: " + st.message);
    if (!st.ok) {
      run.failure = st.message;
      return false;
    }
    joint_state(m, ws, rk4.q(), rk4.qd());
    VecX x(ws.theta.size() + ws.theta_dot.size());
    x << ws.theta, ws.theta_dot;
    run.x.push_back(std::move(x));
    run.q.push_back(rk4.q());
    run.qd.push_back(rk4.qd());
    if (on_sample) on_sample(target);
  }
  run.wall_time = seconds_since(t0);
  return true;
}

// (θ, θ̇) of a twin's sample, its quaternions' signs those of `ref`'s.
VecX twin_state(const Model& m, const TwinSample& s, const VecX& ref) {
  VecX x(ref.size());
  x << s.theta, s.theta_dot;
  align_quaternions(m, ref, x);
  return x;
}

// One trajectory comparison: the runs of both engines and what is known of their errors.
class TrajectoryComparison {
 public:
  TrajectoryComparison(const Model& m, Workspace& ws, const ValidationOptions& o, SimbodyTwin& twin,
                       double t_fd, double simbody_cost, Clock::time_point deadline,
                       const std::function<void(double)>& progress)
      : m(m),
        ws(ws),
        o(o),
        twin(twin),
        t_fd(t_fd),
        simbody_cost(simbody_cost),
        deadline(deadline),
        progress(progress) {}

  TrajectoryReport run(const VecX& q0, const VecX& qd0, TrajectoryReport tr) {
    this->q0 = q0, this->qd0 = qd0;
    sample_times();
    if (!femdyn_run(dt, coarse) || !femdyn_run(dt / 2, fine)) {
      tr.skipped = kSingular + (": " + (coarse.failure.empty() ? fine.failure : coarse.failure));
      return tr;
    }
    rk4_estimate();
    if (!simbody_runs(tr)) return tr;
    if (!refine(tr)) return tr;
    compare(tr);
    return tr;
  }

 private:
  inline static const std::string kSingular = "femdyn's integration failed along the trajectory";
  const Model& m;
  Workspace& ws;
  const ValidationOptions& o;
  SimbodyTwin& twin;
  const double t_fd, simbody_cost;
  const Clock::time_point deadline;
  const std::function<void(double)>& progress;
  VecX q0, qd0;
  std::vector<double> times;  // the samples, on femdyn's grid
  double dt = 0;              // femdyn's coarse step (the fine one dt/2)
  Run coarse, fine;
  std::vector<TwinSample> sim, tight;  // Simbody at its accuracy and 100x tighter
  double done = 0;  // estimated seconds of trajectory work done, for the progress line
  double estimate_rk4 = 0, scale = 1;

  double left() const { return std::chrono::duration<double>(deadline - Clock::now()).count(); }

  // The first step, within half of RK4's linear stability limit at the start (a stiff spring
  // or damper would blow up a run at rk4_step: a diagnosis femdyn check makes the same way);
  // the sample times lie on its grid.
  void sample_times() {
    double first = o.rk4_step;
    if (const Linearization lin = linearize(m, ws, q0, qd0, VecX::Zero(m.n())); lin.status.ok)
      if (const auto stable = largest_stable_step(lin, IntegratorKind::Rk4))
        first = std::min(first, 0.5 * *stable);
    dt = o.t_end / std::max(1.0, std::round(o.t_end / first));
    const int samples = std::max(1, o.samples);
    for (int i = 0; i <= samples; ++i) times.push_back(dt * std::round(o.t_end * i / samples / dt));
  }

  bool femdyn_run(double step, Run& run) {
    const double cost = std::round(o.t_end / step) * 4 * t_fd;
    const double before = done;
    const bool ok = integrate(m, ws, q0, qd0, times, step, run,
                              [&](double t) { progress(before + cost * t / o.t_end); });
    done = before + cost;
    return ok;
  }

  // RK4 is 4th order: x_dt − x_exact ≈ 16/15 (x_dt − x_dt/2); the finer run is 16x better.
  void rk4_estimate() {
    estimate_rk4 = 0, scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      estimate_rk4 = std::max(estimate_rk4, max_abs(coarse.x[i] - fine.x[i]) / 15);
      scale = std::max(scale, max_abs(fine.x[i]));
    }
  }

  // Simbody at its accuracy and 100x tighter (the difference estimates its own error), each
  // bounded by what is left; the tighter run takes about 100^(1/4) = 3.2 times as long.
  bool simbody_runs(TrajectoryReport& tr) {
    TwinRunLimits limits;
    limits.wall_time = std::max(1e-3, left() / (1 + kTightRatio));
    double before = done;
    const double cost = simbody_cost / (1 + kTightRatio);  // the run at its accuracy
    limits.on_sample = [&](double t) { progress(before + cost * t / o.t_end); };
    TwinRun a =
        twin.simulate(q0, qd0, times, o.simbody_accuracy, SimbodyIntegrator::RungeKuttaMerson,
                      TwinSampling::StepToEach, limits);
    if (!a.stats.ok) {
      tr.stopped =
          "Simbody at accuracy " + format_short(o.simbody_accuracy) + ": " + a.stats.failure;
      return false;
    }
    if (kTightRatio * a.stats.wall_time > 2 * left()) {
      tr.stopped = "Simbody at accuracy " + format_short(o.simbody_accuracy / 100) +
                   " would take about " + format_duration(kTightRatio * a.stats.wall_time) + " (" +
                   format_duration(a.stats.wall_time) + " at " + format_short(o.simbody_accuracy) +
                   "), more than the " + format_duration(std::max(0.0, left())) +
                   " left of the budget";
      return false;
    }
    limits.wall_time = std::max(1e-3, left());
    before = done += cost;
    limits.on_sample = [&](double t) { progress(before + kTightRatio * cost * t / o.t_end); };
    TwinRun b =
        twin.simulate(q0, qd0, times, o.simbody_accuracy / 100, SimbodyIntegrator::RungeKuttaMerson,
                      TwinSampling::StepToEach, limits);
    if (!b.stats.ok) {
      tr.stopped =
          "Simbody at accuracy " + format_short(o.simbody_accuracy / 100) + ": " + b.stats.failure;
      return false;
    }
    done += kTightRatio * cost;
    sim = std::move(a.samples);
    tight = std::move(b.samples);
    return true;
  }

  // Halve femdyn's step until its own error estimate (dt against dt/2) is below the target,
  // within max_rk4_steps steps a run and the budget; not at all when Simbody's own estimate
  // already leaves the comparison unresolved.
  bool refine(TrajectoryReport& tr) {
    double simbody_estimate = 0, tight_scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const VecX xs = twin_state(m, sim[i], fine.x[i]), xt = twin_state(m, tight[i], fine.x[i]);
      simbody_estimate = std::max(simbody_estimate, max_abs(xs - xt));
      tight_scale = std::max(tight_scale, max_abs(xt));
    }
    tr.rk4_step = dt / 2;
    if (10 * simbody_estimate + 1e-12 * tight_scale > o.resolved_tolerance * tight_scale) {
      if (estimate_rk4 > o.rk4_target * scale)
        tr.refinement =
            "not halved further: Simbody's own error estimate alone leaves the comparison "
            "unresolved";
      return true;
    }
    while (estimate_rk4 > o.rk4_target * scale) {
      if (o.t_end / dt * 2 > o.max_rk4_steps) {
        tr.refinement = "not halved beyond dt = " + format_short(dt / 2) + " s: the limit of " +
                        format_short(o.max_rk4_steps) + " steps a run";
        break;
      }
      const double next = 2 * fine.wall_time;  // the run at dt/4 against the one at dt/2
      if (next > left()) {
        tr.refinement = "not halved beyond dt = " + format_short(dt / 2) +
                        " s: the run at dt = " + format_short(dt / 4) + " s would take about " +
                        format_duration(next) + ", more than the " +
                        format_duration(std::max(0.0, left())) + " left of the budget (--budget)";
        break;
      }
      dt /= 2;
      std::swap(coarse, fine);
      if (!femdyn_run(dt / 2, fine)) {
        tr.skipped = kSingular + (": " + fine.failure);
        return false;
      }
      tr.rk4_step = dt / 2;
      rk4_estimate();
    }
    return true;
  }

  // The finer runs of both, sample by sample, with both error estimates and the energies.
  void compare(TrajectoryReport& tr) {
    tr.run = true;
    tr.rk4_error_estimate = 0;
    double state_scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const VecX xs = twin_state(m, sim[i], fine.x[i]), xt = twin_state(m, tight[i], fine.x[i]);
      const double err = max_abs(fine.x[i] - xt);
      const double e = energy(m, ws, fine.q[i], fine.qd[i]).total();
      tr.t.push_back(times[i]);
      tr.error.push_back(err);
      tr.energy_femdyn.push_back(e);
      tr.energy_simbody.push_back(tight[i].energy);
      tr.max_state_error = std::max(tr.max_state_error, err);
      tr.rk4_error_estimate =
          std::max(tr.rk4_error_estimate, max_abs(coarse.x[i] - fine.x[i]) / 15);
      tr.simbody_error_estimate = std::max(tr.simbody_error_estimate, max_abs(xs - xt));
      tr.energy_change_femdyn =
          std::max(tr.energy_change_femdyn, std::abs(e - tr.energy_femdyn[0]));
      tr.energy_change_simbody =
          std::max(tr.energy_change_simbody, std::abs(tight[i].energy - tight[0].energy));
      state_scale = std::max(state_scale, max_abs(xt));
    }
    // The two runs may differ by what each integrator gets wrong (with a margin of 10), plus
    // round-off. A comparison whose integrators are not that accurate proves nothing: the motion
    // is unresolved (chaotic over this time, or too fast) and fails with that reason.
    // A closed mechanism's runs are projected onto the constraints, Simbody's to its accuracy
    // (setConstraintTolerance) and femdyn's after every step to 1e-12 (assemble's tolerance):
    // errors of that size, not of the step, that neither estimate sees: the floor is Simbody's
    // accuracy instead of round-off.
    const double floor = tr.constrained ? std::max(1e-12, o.simbody_accuracy) : 1e-12;
    tr.tolerance = 10 * (tr.rk4_error_estimate + tr.simbody_error_estimate) + floor * state_scale;
    tr.resolved = tr.tolerance <= o.resolved_tolerance * state_scale;
  }
};

}  // namespace

// The trajectory from (q0, q̇0), within what is left of the budget at `deadline`.
TrajectoryReport Validator::Impl::trajectory(const VecX& q0, const VecX& qd0,
                                             Clock::time_point deadline,
                                             const std::function<void(double)>& progress) {
  TrajectoryReport tr;
  tr.t_end = o.t_end;
  tr.constrained = !m.constraints.empty();
  if (o.t_end <= 0) {
    tr.skipped = "--t-end 0";
    return tr;
  }
  if (!m.prescribed.empty()) {  // (the twin has no driven joints: its run would be another's)
    tr.skipped = "the model prescribes joint '" + m.prescribed[0].joint +
                 "' in time, which the Simbody twin does not: pointwise only";
    return tr;
  }
  if (!twin->can_simulate(&tr.skipped)) return tr;
  VecX q = q0, qd = qd0;
  if (tr.constrained) {  // a consistent start: Φ = 0, Φ_q q̇ = 0
    std::string why;
    if (!consistent_state(m, q, qd, why)) {
      tr.skipped =
          "femdyn cannot assemble a start (the first state or the neutral posture): " + why;
      return tr;
    }
  }
  TrajectoryComparison comparison(m, ws, o, *twin, t_fd, simbody_cost, deadline, progress);
  return comparison.run(q, qd, tr);
}

}  // namespace femdyn::validation
