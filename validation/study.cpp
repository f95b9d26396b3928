#include "validation/study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "core/integrator.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {
namespace {

using States = std::vector<VecX>;  // x = (θ, θ̇) at each sample

// One sweep: an integrator of one engine over settings from loose to tight.
struct Sweep {
  std::string engine, integrator, setting;
  std::vector<double> values;
  std::function<StudyRun(double)> run;  // one timed run, error not yet filled in
  std::size_t next = 0;
  bool active = true;
};

struct Sampled {
  States x;
  std::vector<double> energy;
  IntegratorStats stats;
  Status status;
};

// femdyn's run: advance_to each sample time, x = (θ, θ̇) of every joint (core joint_state).
Sampled femdyn_run(const Model& m, const IntegratorOptions& o, const StudyOptions& so,
                   const std::vector<double>& times) {
  Sampled s;
  const auto begin = std::chrono::steady_clock::now();  // set-up counts, as Simbody's does
  auto integ = make_integrator(m, o);
  integ->reset(0, so.q0, so.qd0, so.t_end);
  const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  Workspace ws(m);
  const auto sample = [&] {
    joint_state(m, ws, integ->q(), integ->qd());
    VecX x(2 * m.n_theta());
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
  s.stats = integ->stats();
  s.stats.wall_time += setup;
  return s;
}

void score(StudyRun& r, const States& x, const std::vector<double>& energy, const States& ref) {
  if (x.size() != ref.size()) {
    r.ok = false;
    return;
  }
  for (std::size_t k = 0; k < ref.size(); ++k) {
    r.error = std::max(r.error, max_abs(x[k] - ref[k]));
    r.energy_drift = std::max(r.energy_drift, std::abs(energy[k] - energy[0]));
  }
  r.final_error = max_abs(x.back() - ref.back());
  if (!std::isfinite(r.error)) r.ok = false;
}

std::vector<double> decades(int from, int to) {  // 10^-from … 10^-to
  std::vector<double> v;
  for (int k = from; k <= to; ++k) v.push_back(std::pow(10.0, -k));
  return v;
}

}  // namespace

StudyReport run_study(const Model& m, const StudyOptions& o,
                      const std::function<void(const std::string&)>& log) {
  StudyReport rep;
  rep.model = m.name;
  rep.n = m.n();
  rep.t_end = o.t_end;
  rep.q0 = o.q0;
  rep.qd0 = o.qd0;
  rep.conservative = m.torques.empty();
  for (const Body& b : m.bodies) rep.conservative = rep.conservative && b.joint.damping == 0;
  std::vector<double> times;
  for (int k = 1; k <= o.samples; ++k) times.push_back(o.t_end * k / o.samples);
  std::vector<double> with_zero = times;  // Simbody samples t = 0 too
  with_zero.insert(with_zero.begin(), 0.0);

  // Reference: Dormand–Prince landing on every sample, at rtol 1e-14 and 1e-13.
  const auto reference = [&](double rtol) {
    IntegratorOptions ro{
        .kind = IntegratorKind::Dopri,
        .adaptive = {
            .rtol = rtol, .atol = rtol, .max_steps = 100'000'000, .stop_at_outputs = true}};
    Sampled s = femdyn_run(m, ro, o, times);
    if (!s.status.ok)
      throw std::runtime_error("the reference solution failed: " + s.status.message);
    return s;
  };
  rep.reference_rtol = 1e-14;
  rep.reference_method =
      "femdyn dopri (Dormand-Prince 5(4), SUNDIALS ARKODE) landing on each "
      "sample, rtol = atol = 1e-14";
  const Sampled ref = reference(rep.reference_rtol), coarse = reference(10 * rep.reference_rtol);
  for (std::size_t k = 0; k < ref.x.size(); ++k)
    rep.reference_error = std::max(rep.reference_error, max_abs(ref.x[k] - coarse.x[k]));
  rep.resolution = 100 * rep.reference_error;

  // femdyn sweeps. Fixed steps: N = samples·2^k steps, so the samples lie on the grid.
  std::vector<Sweep> femdyn, simbody;
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
    s.run = [&, kind](double value) {
      IntegratorOptions io{.kind = kind};
      if (is_adaptive(kind))
        io.adaptive = {.rtol = value, .atol = value, .max_steps = 100'000'000};
      else
        io.fixed = {.dt = value};
      const Sampled r = femdyn_run(m, io, o, times);
      StudyRun run{.engine = "femdyn",
                   .integrator = integrator_name(kind),
                   .setting = is_adaptive(kind) ? "rtol" : "dt",
                   .value = value};
      run.wall_time = r.stats.wall_time;
      run.steps = r.stats.steps;
      run.rhs_evals = r.stats.rhs_evals;
      run.ok = r.status.ok;
      run.failure = r.status.message;
      if (run.ok) score(run, r.x, r.energy, ref.x);
      return run;
    };
    femdyn.push_back(std::move(s));
  }

  // Simbody sweeps over accuracies, when the twin can integrate the model.
  SimbodyTwin twin(twin_model(m));
  std::string why_not;
  if (twin.can_simulate(&why_not)) {
    for (SimbodyIntegrator which : simbody_integrators()) {
      Sweep s{"Simbody",
              simbody_integrator_name(which),
              "accuracy",
              o.quick ? decades(2, 8) : decades(2, 10),
              {}};
      s.run = [&, which](double accuracy) {
        const TwinRun r = twin.simulate(o.q0, o.qd0, with_zero, accuracy, which);
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
          score(run, x, energy, ref.x);
        }
        return run;
      };
      simbody.push_back(std::move(s));
    }
  } else {
    rep.notes.push_back("Simbody's integrators were not run: " + why_not);
  }

  // Round-robin, the engines alternating; a sweep stops after a run over budget or an error
  // below the reference's resolution (a failed run, e.g. a step beyond the stability limit,
  // does not stop it: a finer setting may succeed).
  std::vector<Sweep*> order;
  for (std::size_t i = 0; i < std::max(femdyn.size(), simbody.size()); ++i) {
    if (i < femdyn.size()) order.push_back(&femdyn[i]);
    if (i < simbody.size()) order.push_back(&simbody[i]);
  }
  const double budget = o.quick ? 0.2 : o.run_budget;
  for (bool any = true; any;) {
    any = false;
    for (Sweep* s : order) {
      if (!s->active || s->next >= s->values.size()) continue;
      any = true;
      StudyRun r = s->run(s->values[s->next++]);
      r.times = {r.wall_time};
      r.resolved = r.ok && r.error >= rep.resolution;
      if (log)
        log(r.engine + " " + r.integrator + " " + r.setting + " " + format_number(r.value, "%.3g") +
            (r.ok ? ": error " + format_number(r.error, "%.2e") + ", " +
                        format_number(r.wall_time, "%.3g s")
                  : ": failed: " + r.failure));
      s->active = r.wall_time < budget && (!r.ok || r.error >= rep.resolution);
      rep.runs.push_back(std::move(r));
    }
  }

  // Repeats of the short runs, in rounds, in the same alternating order.
  const int repeats = o.quick ? 1 : o.repeats;
  for (int round = 1; round < repeats; ++round) {
    for (Sweep* s : order)
      for (StudyRun& r : rep.runs)
        if (r.ok && r.engine == s->engine && r.integrator == s->integrator &&
            r.wall_time < o.repeat_below)
          r.times.push_back(s->run(r.value).wall_time);
  }
  for (StudyRun& r : rep.runs) {
    std::vector<double> t = r.times;
    std::sort(t.begin(), t.end());
    r.wall_time = t.empty() ? 0 : t[t.size() / 2];
  }
  return rep;
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
