#include "validation/study.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <thread>

#include "core/joints/kernel.hpp"
#include "core/model/errors.hpp"
#include "sim/integrator.hpp"
#include "sim/recorded_run.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {
namespace {

using States = std::vector<VecX>;  // x = (θ, θ̇) at each sample

// One sweep: an integrator of one engine over settings from loose to tight.
struct Sweep {
  std::string engine, integrator, setting;
  std::vector<double> values;
  // One timed run at a setting, error not yet filled in; stopped past `limit` s (0: none).
  std::function<StudyRun(double value, double limit)> run;
  std::size_t next = 0;
  bool active = true;
};

struct Sampled {
  States x;
  std::vector<double> energy;
  IntegratorStats stats;
  Status status;
  double t_reached = 0;
};

// Bounds on a femdyn run: stopped past `wall` seconds (0: none), and `watch(t)` told the
// model time reached, both asked inside the steps at most every 20 ms (Motion::set_interrupt).
// An unbounded run sets no interrupt, so that its timing is the integrator's alone.
struct RunLimit {
  double wall = 0;
  std::function<void(double t)> watch;
};

// femdyn's run: advance_to each sample time, x = (θ, θ̇) of every joint (core joint_state).
Sampled femdyn_run(const Model& m, const IntegratorOptions& o, const StudyOptions& so,
                   const std::vector<double>& times, const RunLimit& limit = {}) {
  Sampled s;
  const auto begin = std::chrono::steady_clock::now();  // set-up counts, as Simbody's does
  const auto since_begin = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  };
  auto integ = make_integrator(m, o);
  integ->reset(0, so.q0, so.qd0, so.t_end);
  const double setup = since_begin();
  std::optional<Motion::InterruptScope> bounded;
  if (limit.wall > 0 || limit.watch)
    bounded.emplace(integ->motion(), [&] {
      if (limit.watch) limit.watch(integ->t());
      return limit.wall > 0 && since_begin() > limit.wall;
    });
  Workspace ws(m);
  const auto sample = [&] {
    joint_state(m, ws, integ->q(), integ->qd());
    VecX x(ws.theta.size() + ws.theta_dot.size());
    x << ws.theta, ws.theta_dot;
    s.x.push_back(std::move(x));
    s.energy.push_back(integ->motion().energy_at(integ->y().data()).total());
  };
  sample();
  for (double t : times) {
    s.status = integ->advance_to(t);
    if (!s.status.ok) break;
    sample();
  }
  if (s.status.interrupted)
    s.status.message = "stopped at t = " + format_short(integ->t()) + " s of " +
                       format_short(so.t_end) + " s, past " + format_short(limit.wall) +
                       " s of wall time";
  s.t_reached = integ->t();
  s.stats = integ->stats();
  s.stats.wall_time += setup;
  return s;
}

// The sample times t_end·k/samples, k = 1 … samples.
std::vector<double> sample_times(const StudyOptions& o) {
  std::vector<double> times;
  for (int k = 1; k <= o.samples; ++k) times.push_back(o.t_end * k / o.samples);
  return times;
}

// The reference method: Dormand–Prince landing on every sample at rtol = atol.
IntegratorOptions reference_options(double rtol) {
  return {
      .kind = IntegratorKind::Dopri,
      .adaptive = {.rtol = rtol, .atol = rtol, .max_steps = 100'000'000, .stop_at_outputs = true}};
}

// x ⊖ ref joint by joint: (ξ, θ̇ − θ̇_ref) with ξ = θ ⊖ θ_ref on each joint's manifold (θ − θ_ref
// on a flat joint; a quaternion's difference is the rotation vector between the two, so q and −q
// are one). x = (θ, θ̇) of n_θq + nθ entries; the result has 2 nθ, one per rate.
VecX state_difference(const Model& m, const VecX& ref, const VecX& x) {
  const int nt = m.n_theta(), nq = m.n_theta_q;
  VecX d(2 * nt);
  for (const Body& b : m.bodies)
    if (const Joint& J = b.joint; moves(J))
      configuration_difference(J, ref.data() + J.idx_q, x.data() + J.idx_q, d.data() + J.idx_v);
  d.tail(nt) = x.tail(nt) - ref.segment(nq, nt);
  return d;
}

// The error measure (study.hpp): each component of x ⊖ ref (one per rate, for θ and θ̇) in a
// group — angle, angular rate, position, speed — whose size S_g is the reference's largest
// magnitude in that group, measured from the neutral configuration (x ⊖ (θ_0, 0)).
struct Measure {
  const Model& model;
  std::vector<int> group;        // per component of x ⊖ ref
  std::array<double, 4> size{};  // S_g; 1 where a group is identically zero
  std::array<bool, 4> present{};
  static constexpr const char* kName[4] = {"angle", "angular rate", "position", "speed"};
  static constexpr const char* kUnit[4] = {"rad", "rad/s", "m", "m/s"};

  Measure(const Model& m, const States& ref) : model(m) {
    const int nt = m.n_theta();
    for (int half = 0; half < 2; ++half)
      for (int j = 0; j < nt; ++j) {
        const Joint& J = m.bodies[m.theta_joint[j]].joint;
        group.push_back((is_translation(J, j - J.idx_v) ? 2 : 0) + half);
      }
    VecX neutral = VecX::Zero(m.n_theta_q + nt);
    for (const Body& b : m.bodies)
      if (moves(b.joint)) neutral_configuration(b.joint, neutral.data() + b.joint.idx_q);
    for (const VecX& x : ref) {
      const VecX d = state_difference(m, neutral, x);
      for (std::size_t i = 0; i < group.size(); ++i) {
        size[group[i]] = std::max(size[group[i]], std::abs(d[static_cast<Eigen::Index>(i)]));
        present[group[i]] = true;
      }
    }
    for (double& s : size)
      if (!(s > 0)) s = 1;
  }
  // The relative error of one sample, and the absolute errors of its positions and rates.
  double relative(const VecX& x, const VecX& ref, double* position = nullptr,
                  double* rate = nullptr) const {
    if (!x.allFinite()) return std::numeric_limits<double>::quiet_NaN();
    const VecX d = state_difference(model, ref, x);
    double e = 0;
    const std::size_t half = group.size() / 2;
    for (std::size_t i = 0; i < group.size(); ++i) {
      const double di = std::abs(d[static_cast<Eigen::Index>(i)]);
      if (!std::isfinite(di)) return di;
      e = std::max(e, di / size[group[i]]);
      double* abs = i < half ? position : rate;
      if (abs) *abs = std::max(*abs, di);
    }
    return e;
  }
};

void score(StudyRun& r, const States& x, const std::vector<double>& energy, const States& ref,
           const Measure& measure) {
  if (x.size() != ref.size()) {
    r.ok = false;
    return;
  }
  for (std::size_t k = 0; k < ref.size(); ++k) {
    const double e = measure.relative(x[k], ref[k], &r.position_error, &r.rate_error);
    if (!std::isfinite(e)) {  // (std::max would drop a NaN)
      r.ok = false;
      r.failure = "NaN or Inf in the state at sample " + std::to_string(k);
      return;
    }
    r.error = std::max(r.error, e);
    r.energy_drift = std::max(r.energy_drift, std::abs(energy[k] - energy[0]));
  }
  r.final_error = measure.relative(x.back(), ref.back());
}

std::vector<double> decades(int from, int to) {  // 10^-from … 10^-to
  std::vector<double> v;
  for (int k = from; k <= to; ++k) v.push_back(std::pow(10.0, -k));
  return v;
}

double median(std::vector<double> t) {
  if (t.empty()) return 0;
  std::sort(t.begin(), t.end());
  const std::size_t h = t.size() / 2;
  return t.size() % 2 ? t[h] : 0.5 * (t[h - 1] + t[h]);
}

}  // namespace

std::vector<double> load_average() {
  std::ifstream f("/proc/loadavg");
  std::vector<double> out(3);
  for (double& v : out)
    if (!(f >> v)) return {};
  return out;
}

StudyMachine study_machine() {
  StudyMachine m;
  std::ifstream cpu("/proc/cpuinfo");
  std::string line;
  while (std::getline(cpu, line))
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      m.cpu = line.substr(line.find(':') + 1);
      m.cpu.erase(0, m.cpu.find_first_not_of(" \t"));
      break;
    }
  m.cores = static_cast<int>(std::thread::hardware_concurrency());
  return m;
}

namespace {

// One work-precision study: its samples, the reference solution and the measure of errors
// against it, the sweeps of both engines, and the report they fill.
class Study {
 public:
  Study(const Model& m, const StudyOptions& o) : m(m), o(o), times(sample_times(o)) {
    with_zero = times;  // Simbody samples t = 0 too
    with_zero.insert(with_zero.begin(), 0.0);
    describe();
  }

  StudyReport run(const std::function<void(const std::string&)>& log) {
    measure_reference();
    femdyn_sweeps();
    const TwinModel tm = twin_model(m);
    note_formulation(tm);
    SimbodyTwin twin(tm);
    twin.close_loops(!m.constraints.empty());  // the closed mechanism, as femdyn integrates it
    simbody_sweeps(twin);
    std::vector<Sweep*> order;  // the engines alternating
    for (std::size_t i = 0; i < std::max(femdyn.size(), simbody.size()); ++i) {
      if (i < femdyn.size()) order.push_back(&femdyn[i]);
      if (i < simbody.size()) order.push_back(&simbody[i]);
    }
    warm_up(order, log);
    timed_runs(order);
    rep.machine.load_end = load_average();
    return std::move(rep);
  }

 private:
  const Model& m;
  const StudyOptions& o;
  std::vector<double> times, with_zero;
  StudyReport rep;
  Sampled ref;
  std::optional<Measure> measure;
  std::vector<Sweep> femdyn, simbody;
  std::vector<std::pair<Sweep*, std::size_t>> made;  // each run's sweep and index in rep.runs

  void describe() {
    rep.machine = study_machine();
    rep.machine.load_start = load_average();
    rep.model = m.name;
    rep.n = m.n();
    rep.t_end = o.t_end;
    rep.samples = o.samples;
    rep.q0 = o.q0;
    rep.qd0 = o.qd0;
    rep.interpolate = o.interpolate;
    rep.conservative = conservative(m, false);  // (a driven model is refused)
    rep.sampling =
        o.interpolate
            ? "both engines step freely and interpolate at the samples: femdyn's dopri and bdf by "
              "their dense output, Simbody's integrators by Integrator::stepTo with no scheduled "
              "event (cubic Hermite; CPodes its own), neither stepping past the last sample; "
              "femdyn's rk4 and euler land on the samples, their steps dividing the sample spacing"
            : "both engines land on every sample: femdyn's dopri and bdf shorten a step to end on "
              "it (stop_at_outputs), Simbody's integrators through TimeStepper (each sample a "
              "scheduled event; CPodes still interpolates inside CPODES); femdyn's rk4 and euler "
              "land on the samples, their steps dividing the sample spacing";
  }

  // Reference: Dormand–Prince landing on every sample, at rtol 1e-14 and 1e-13; stopped past
  // the study's budget.
  Sampled reference(double rtol) const {
    const std::string run = "reference (rtol " + format_short(rtol) + ")";
    RunLimit limit{.wall = o.budget};
    if (o.reference_progress) limit.watch = [&](double t) { o.reference_progress(run, t); };
    Sampled s = femdyn_run(m, reference_options(rtol), o, times, limit);
    if (s.status.interrupted)
      throw femdyn::Error("the " + run + " passed the budget: " + s.status.message +
                          " (shorten --t-end, or raise --budget)");
    if (!s.status.ok) throw femdyn::Error("the reference solution failed: " + s.status.message);
    return s;
  }

  void measure_reference() {
    rep.reference_rtol = 1e-14;
    rep.reference_method =
        "femdyn dopri (Dormand-Prince 5(4), SUNDIALS ARKODE) landing on each "
        "sample, rtol = atol = 1e-14";
    ref = reference(rep.reference_rtol);
    const Sampled coarse = reference(10 * rep.reference_rtol);
    rep.reference_wall = ref.stats.wall_time + coarse.stats.wall_time;
    measure.emplace(m, ref.x);
    for (int g = 0; g < 4; ++g)
      if (measure->present[g])
        rep.scales.push_back({Measure::kName[g], measure->size[g], Measure::kUnit[g]});
    for (std::size_t k = 0; k < ref.x.size(); ++k)
      rep.reference_error = std::max(rep.reference_error, measure->relative(coarse.x[k], ref.x[k]));
    rep.resolution = 100 * rep.reference_error;
  }

  // femdyn sweeps. Fixed steps: N = samples·2^k steps, so the samples lie on the grid.
  void femdyn_sweeps() {
    const int doublings = o.quick ? 6 : 14;
    for (IntegratorKind kind : kIntegrators) {
      Sweep s{"femdyn", integrator_name(kind), is_adaptive(kind) ? "rtol" : "dt", {}, {}};
      if (is_adaptive(kind)) {
        s.values = o.quick ? decades(3, 9) : decades(3, kind == IntegratorKind::Bdf ? 11 : 12);
      } else {
        const int first = kind == IntegratorKind::Euler ? 2 : 0;
        for (int k = first; k <= first + doublings; ++k)
          s.values.push_back(o.t_end / (o.samples * std::pow(2.0, k)));
      }
      s.run = [this, kind](double value, double limit) {
        IntegratorOptions io{.kind = kind};
        if (is_adaptive(kind))
          io.adaptive = {.rtol = value,
                         .atol = value,
                         .max_steps = 100'000'000,
                         .stop_at_outputs = !o.interpolate};
        else
          io.fixed = {.dt = value};
        const Sampled r = femdyn_run(m, io, o, times, {.wall = limit});
        StudyRun run{.engine = "femdyn",
                     .integrator = integrator_name(kind),
                     .setting = is_adaptive(kind) ? "rtol" : "dt",
                     .value = value};
        run.wall_time = r.stats.wall_time;
        run.steps = r.stats.steps;
        run.rhs_evals = r.stats.rhs_evals;
        run.ok = r.status.ok;
        run.failure = r.status.message;
        if (run.ok) score(run, r.x, r.energy, ref.x, *measure);
        return run;
      };
      femdyn.push_back(std::move(s));
    }
  }

  // Whether both engines integrate the same equations (a coupled or closed model: not).
  void note_formulation(const TwinModel& tm) {
    if (tm.closed_loop()) {
      rep.same_formulation = false;
      rep.femdyn_formulation = "reduced law";
      rep.simbody_formulation = "constrained loop";
      rep.notes.push_back(
          "not the same formulation: femdyn integrates the reduced law (" + std::to_string(m.n()) +
          " coordinates; the coupled joints follow θ = g(q)), Simbody's twin a constrained loop (" +
          std::to_string(tm.n_theta()) + " joints, " + std::to_string(tm.laws.size()) +
          " coupled joint(s) and " + std::to_string(tm.rods.size()) +
          " rod(s) as CoordinateCoupler and Ball constraints, kept on them by projection). "
          "The times compare the two formulations, not the two engines on the same equations.");
    } else if (tm.n_theta() > tm.n()) {
      rep.same_formulation = false;
      rep.femdyn_formulation = "reduced coordinates";
      rep.simbody_formulation = "coordinate couplers";
      rep.notes.push_back(
          "not the same formulation: femdyn integrates the reduced coordinates (" +
          std::to_string(m.n()) + " of them, θ = C q + θ0), Simbody's twin all " +
          std::to_string(tm.n_theta()) +
          " joints with the coupling as CoordinateCoupler constraints, kept on them by "
          "projection. The times compare the two formulations, not the two engines on the same "
          "equations.");
    } else {
      rep.femdyn_formulation = rep.simbody_formulation = "tree coordinates";
    }
    if (!m.constraints.empty())
      rep.notes.push_back(
          "loop constraints: both engines integrate the tree with its " +
          std::to_string(m.constraint_rows) +
          " constraint equations from the same assembled start; femdyn with Baumgarte's "
          "stabilisation (20/s) and projection after a step that leaves them, Simbody with its "
          "projection after every step");
  }

  // Simbody sweeps over accuracies, when the twin can integrate the model.
  void simbody_sweeps(SimbodyTwin& twin) {
    std::string why_not;
    if (!twin.can_simulate(&why_not)) {
      rep.notes.push_back("Simbody's integrators were not run: " + why_not);
      return;
    }
    const TwinSampling twin_sampling =
        o.interpolate ? TwinSampling::Interpolate : TwinSampling::StepToEach;
    for (SimbodyIntegrator which : simbody_integrators()) {
      Sweep s{"Simbody",
              simbody_integrator_name(which),
              "accuracy",
              o.quick ? decades(2, 8) : decades(2, 10),
              {}};
      s.run = [this, &twin, which, twin_sampling](double accuracy, double limit) {
        const TwinRun r = twin.simulate(o.q0, o.qd0, with_zero, accuracy, which, twin_sampling,
                                        {.wall_time = limit});
        StudyRun run{.engine = "Simbody",
                     .integrator = simbody_integrator_name(which),
                     .setting = "accuracy",
                     .value = accuracy};
        run.wall_time = r.stats.wall_time;
        run.steps = r.stats.steps;
        run.rhs_evals = r.stats.realizations;
        run.ok = r.stats.ok;
        run.failure = r.stats.failure;
        if (run.ok) {
          States x;
          std::vector<double> energy;
          for (const TwinSample& t : r.samples) {
            VecX v(t.theta.size() + t.theta_dot.size());
            v << t.theta, t.theta_dot;
            x.push_back(std::move(v));
            energy.push_back(t.energy);
          }
          score(run, x, energy, ref.x, *measure);
        }
        return run;
      };
      simbody.push_back(std::move(s));
    }
  }

  // Round-robin, the engines alternating: each run once, as the warm-up of its setting, whose
  // error and time decide whether the sweep goes on. A sweep stops after a run over budget or
  // an error below the reference's resolution (a failed run, e.g. a step beyond the stability
  // limit, does not stop it: a finer setting may succeed).
  void warm_up(const std::vector<Sweep*>& order,
               const std::function<void(const std::string&)>& log) {
    const double budget = o.quick ? 0.2 : o.run_budget;
    for (bool any = true; any;) {
      any = false;
      for (Sweep* s : order) {
        if (!s->active || s->next >= s->values.size()) continue;
        any = true;
        StudyRun r = s->run(s->values[s->next++], o.run_limit());
        r.warm_up_time = r.wall_time;
        r.resolved = r.ok && r.error >= rep.resolution;
        if (log)
          log(r.engine + " " + r.integrator + " " + r.setting + " " +
              format_number(r.value, "%.3g") +
              (r.ok ? ": error " + format_number(r.error, "%.2e") + ", warm-up " +
                          format_number(r.wall_time, "%.3g s")
                    : ": failed: " + r.failure));
        s->active = r.wall_time < budget && (!r.ok || r.error >= rep.resolution);
        made.emplace_back(s, rep.runs.size());
        rep.runs.push_back(std::move(r));
      }
    }
  }

  // The timed runs, in rounds, in the same alternating order; a failed run keeps its one time.
  void timed_runs(const std::vector<Sweep*>& order) {
    rep.timed_repeats = o.quick ? 3 : std::max(1, o.repeats);
    rep.timed_repeats_long = o.quick ? 3 : std::max(1, o.long_repeats);
    const auto wanted = [&](const StudyRun& r) {
      return !r.ok ? 0
                   : (r.warm_up_time < o.repeat_below ? rep.timed_repeats : rep.timed_repeats_long);
    };
    for (int round = 0; round < std::max(rep.timed_repeats, rep.timed_repeats_long); ++round)
      for (Sweep* s : order)
        for (const auto& [sweep, i] : made) {
          StudyRun& r = rep.runs[i];
          if (sweep != s || round >= wanted(r)) continue;
          const StudyRun again = s->run(r.value, 0);
          r.times.push_back(again.wall_time);
          if (again.steps != r.steps)  // a run is deterministic: the same steps every time
            rep.notes.push_back(r.engine + " " + r.integrator + " " + r.setting + " " +
                                format_number(r.value, "%.3g") + " took " +
                                std::to_string(again.steps) + " steps in a timed run, " +
                                std::to_string(r.steps) + " in its warm-up");
        }
    for (StudyRun& r : rep.runs) {
      if (r.times.empty()) r.times = {r.warm_up_time};
      r.wall_time = median(r.times);
    }
  }
};

}  // namespace

StudyEstimate estimate_study(const Model& m, const StudyOptions& o) {
  const Sampled probe = femdyn_run(m, reference_options(1e-14), o, sample_times(o),
                                   {.wall = StudyEstimate::kProbeSeconds});
  if (!probe.status.ok && !probe.status.interrupted)
    throw femdyn::Error("the reference solution failed: " + probe.status.message);
  StudyEstimate e{.probe_t = probe.t_reached, .probe_wall = probe.stats.wall_time};
  const double runs = 1 + std::pow(10.0, -0.2);  // rtol 1e-14, then 1e-13
  e.reference = e.probe_t > 0 ? runs * e.probe_wall * o.t_end / e.probe_t
                              : std::numeric_limits<double>::infinity();
  return e;
}

StudyReport run_study(const Model& m, const StudyOptions& o,
                      const std::function<void(const std::string&)>& log) {
  return Study(m, o).run(log);
}

const StudyRun* fastest(const StudyReport& rep, const std::string& engine, double target) {
  const StudyRun* best = nullptr;
  for (const StudyRun& r : rep.runs)
    if (r.engine == engine && r.resolved && r.error <= target &&
        (!best || r.wall_time < best->wall_time))
      best = &r;
  return best;
}

}  // namespace femdyn::validation
