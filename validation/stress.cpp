#include "validation/stress.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "sim/integrator.hpp"
#include "sim/stability.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {
namespace {

struct Run {
  std::vector<VecX> x;  // (q, q̇) at the samples
  std::vector<double> balance, scale;
  IntegratorStats stats;
  Status status;
};

Run integrate(const Model& m, const IntegratorOptions& o, const StressScenario& s,
              const std::vector<double>& times, bool energies) {
  Run r;
  auto integ = make_integrator(m, o);
  integ->reset(0, s.q0, s.qd0, s.t_end);
  const double E0 = energies ? integ->motion().energy_at(integ->y().data()).total() : 0;
  for (double t : times) {
    r.status = integ->advance_to(t);
    if (!r.status.ok) break;
    r.x.push_back(integ->y().head(2 * m.n()));
    if (energies) {
      const Energy E = integ->motion().energy_at(integ->y().data());
      r.balance.push_back(std::abs(E.total() - E0 - integ->work()));
      r.scale.push_back(std::max({std::abs(E.total()), E.kinetic, std::abs(E0)}));
    }
  }
  r.stats = integ->stats();
  return r;
}

double max_error(const std::vector<VecX>& x, const std::vector<VecX>& ref) {
  if (x.size() != ref.size()) return -1;
  double e = 0;
  for (std::size_t k = 0; k < ref.size(); ++k)
    e = std::max(e, (x[k] - ref[k]).cwiseAbs().maxCoeff());
  return std::isfinite(e) ? e : -1;
}

}  // namespace

StressResult refused_case(const std::string& why) {
  StressResult r;
  r.refused = why;
  r.verdict = "refused: " + why;
  return r;
}

StressResult run_stress(const Model& m, const StressScenario& s) {
  StressResult r;
  r.n = m.n();
  const int samples = s.large ? 2 : 10;
  std::vector<double> times;
  for (int k = 1; k <= samples; ++k) times.push_back(s.t_end * k / samples);

  // The initial state must have a regular M^s.
  Workspace ws(m);
  if (const Status st = forward_dynamics(m, ws, s.q0, s.qd0, VecX::Zero(m.n())); !st.ok)
    return refused_case("at the initial state: " + st.message);
  Linearization lin;
  bool stiffest_dissipative = false;  // the stiffness bdf cures (femdyn check's rule)
  if (!s.large) {
    lin = linearize(m, ws, s.q0, s.qd0, VecX::Zero(m.n()));
    r.stiffest = std::abs(lin.stiffest);
    if (const std::vector<Mode> md = modes(lin, has_dampers(m)); !md.empty())
      stiffest_dissipative = md.front().dissipative();
  }

  // Reference: Dormand–Prince, or BDF when Dormand–Prince cannot (stiff).
  IntegratorOptions ref_options{
      .kind = IntegratorKind::Dopri,
      .adaptive = {.rtol = 1e-10, .atol = 1e-12, .max_steps = 200'000, .stop_at_outputs = true}};
  if (s.large) ref_options = {.kind = IntegratorKind::Rk4, .fixed = {.dt = s.dt / 2}};
  Run ref = integrate(m, ref_options, s, times, true);
  r.reference = s.large ? "rk4 at dt/2" : "dopri rtol 1e-10";
  if (!ref.status.ok && !s.large) {
    ref_options.kind = IntegratorKind::Bdf;
    ref = integrate(m, ref_options, s, times, true);
    r.reference = "bdf rtol 1e-10";
  }
  if (!ref.status.ok)
    return refused_case("no integrator resolves the motion: " + ref.status.message);
  double state_scale = 1;
  for (const VecX& x : ref.x) state_scale = std::max(state_scale, x.cwiseAbs().maxCoeff());
  for (std::size_t k = 0; k < ref.balance.size(); ++k)
    r.energy_error = std::max(r.energy_error, ref.scale[k] > 0 ? ref.balance[k] / ref.scale[k] : 0);

  // Conditioning along the reference (at its ends only for a large model).
  r.cond_min = INFINITY;
  for (const VecX& x : s.large ? std::vector<VecX>{ref.x.front(), ref.x.back()} : ref.x) {
    evaluate(m, ws, x.head(m.n()), x.tail(m.n()), VecX());
    const MassMatrixHealth h = mass_matrix_health(ws.Ms);
    r.cond_min = std::min(r.cond_min, h.condition);
    r.cond_max = std::max(r.cond_max, h.condition);
    r.asymmetry = std::max(r.asymmetry, h.asymmetry);
    r.positive_definite = r.positive_definite && h.positive_definite;
  }

  // Every integrator at the scenario's step or tolerance; the fixed-step ones' stable limit.
  // A trial run covers at least kMinSteps steps and kPeriods periods of the stiffest mode, however
  // long or short the scenario is, and is stable when it neither diverges nor fails.
  const double period = r.stiffest > 0 ? 2 * std::numbers::pi / r.stiffest : 0;
  const auto stable = [&](IntegratorKind kind, double dt) {
    const double span = std::max(kPeriods * period, kMinSteps * dt);
    auto integ =
        make_integrator(m, {.kind = kind, .fixed = {.dt = dt, .max_steps = 1'000'000'000}});
    integ->reset(0, s.q0, s.qd0, span);
    return integ->advance_to(span).ok;
  };
  for (IntegratorKind kind : kIntegrators) {
    StressIntegrator it{.name = integrator_name(kind)};
    if (s.large && is_adaptive(kind)) {
      it.failure = "not run: too large for a quick adaptive run";
      r.integrators.push_back(std::move(it));
      continue;
    }
    IntegratorOptions o{.kind = kind};
    if (is_adaptive(kind))
      o.adaptive = {.rtol = 1e-6, .atol = 1e-8, .max_steps = 200'000, .stop_at_outputs = true};
    else
      o.fixed = {.dt = s.dt};
    const Run run = integrate(m, o, s, times, false);
    it.steps = run.stats.steps;
    if (run.status.ok)
      it.error = max_error(run.x, ref.x) / state_scale;
    else
      it.failure = run.status.message;
    if (!is_adaptive(kind) && r.stiffest > 0) {
      if (const auto h = largest_stable_step(lin, kind); h && std::isfinite(*h))
        it.theory_step = *h;
      // Bracket from the linear estimate by factors of 2 (every explicit method here is
      // unstable beyond h |λ| = 10), then bisect on log h to 1 %.
      double lo = 1 / r.stiffest;
      while (!stable(kind, lo) && lo * r.stiffest > 1e-6) lo /= 2;
      double hi = 2 * lo;
      while (stable(kind, hi) && hi * r.stiffest < 100) hi *= 2;
      while (hi / lo > 1.01) {
        const double mid = lo * std::sqrt(hi / lo);
        (stable(kind, mid) ? lo : hi) = mid;
      }
      it.largest_stable_step = lo;
    }
    r.integrators.push_back(std::move(it));
  }
  if (s.large)
    r.search_note =
        "no step search: the linearisation (4n evaluations and a dense eigenproblem of 2n = " +
        std::to_string(2 * m.n()) + ") takes too long at this size";
  else if (r.stiffest == 0)
    r.search_note = "no step search: no mode at the initial state (every step is stable)";

  // Simbody.
  if (s.large) {
    r.simbody_note = "not run (size)";
  } else {
    try {
      SimbodyTwin twin(twin_model(m));
      std::vector<double> with_zero = times;
      with_zero.insert(with_zero.begin(), 0.0);
      std::string why;
      if (!twin.can_simulate(&why)) {
        r.simbody_note = why;
      } else {
        const TwinRun run =
            twin.simulate(s.q0, s.qd0, with_zero, 1e-12, SimbodyIntegrator::RungeKuttaMerson);
        if (!run.stats.ok) {
          r.simbody_note = "Simbody failed: " + run.stats.failure;
        } else {
          std::vector<VecX> x;
          for (std::size_t k = 1; k < run.samples.size(); ++k) {
            VecX v(2 * m.n_theta());
            v << run.samples[k].theta, run.samples[k].theta_dot;
            x.push_back(std::move(v));
          }
          std::vector<VecX> ref_theta;
          for (const VecX& y : ref.x) {
            VecX v(2 * m.n_theta());
            v << m.C * y.head(m.n()) + m.theta0, m.C * y.tail(m.n());
            ref_theta.push_back(std::move(v));
          }
          r.simbody_error = max_error(x, ref_theta) / state_scale;
        }
      }
    } catch (const std::exception& e) {
      r.simbody_note = std::string("Simbody cannot hold the model: ") + e.what();
    }
  }

  // Verdict.
  const StressIntegrator& rk4 = r.integrators[0];
  const bool stiff = (rk4.largest_stable_step >= 0 && rk4.largest_stable_step < 1e-4) ||
                     r.reference.rfind("bdf", 0) == 0;
  if (!r.positive_definite)
    r.verdict = "refused: M^s loses definiteness along the motion";
  else if (r.cond_max > 1e12)
    r.verdict = "ill-conditioned: cond(M^s) up to " + format_short(r.cond_max) +
                ", q̈ loses about " + format_short(std::log10(r.cond_max)) + " of 16 digits";
  else if (stiff && stiffest_dissipative)
    r.verdict =
        "stable only with bdf: rk4 needs dt < " + format_short(rk4.largest_stable_step) + " s";
  else if (stiff)  // as femdyn check advises: bdf is stable here, but by damping the oscillation
    r.verdict = "stiff and undamped: rk4 needs dt < " + format_short(rk4.largest_stable_step) +
                " s; bdf stays stable only by damping the mode numerically (remove, damp or "
                "resolve it)";
  else
    r.verdict = "stable";
  return r;
}

}  // namespace femdyn::validation
