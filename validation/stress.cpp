#include "validation/stress.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "core/loops/assembly.hpp"
#include "sim/integrator.hpp"
#include "sim/stability.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {
namespace {

struct StressRun {
  std::vector<VecX> x;  // (q, q̇) at the samples
  std::vector<double> balance, scale;
  IntegratorStats stats;
  Status status;
  Motion::ConstraintResidual residual;  // max |Φ|∞, |Φ_q v|∞ over the samples (closed loops)
  std::vector<VecX> q;                  // the configurations at the samples (closed loops)
};

StressRun integrate(const Model& m, const IntegratorOptions& o, const StressScenario& s,
                    const std::vector<double>& times, bool energies) {
  StressRun r;
  auto integ = make_integrator(m, o);
  integ->reset(0, s.q0, s.qd0, s.t_end);
  const double E0 = energies ? integ->motion().energy_at(integ->y().data()).total() : 0;
  for (double t : times) {
    r.status = integ->advance_to(t);
    if (!r.status.ok) break;
    r.x.push_back(integ->y().head(2 * m.n()));
    if (integ->motion().constrained()) {
      const Motion::ConstraintResidual c = integ->motion().constraint_residual(integ->y().data());
      r.residual.position = std::max(r.residual.position, c.position);
      r.residual.velocity = std::max(r.residual.velocity, c.velocity);
      r.q.push_back(integ->q());
    }
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

// Closed loops: (q0, q̇0) moved onto the constraints (docs/loops.md#assembly), and the
// equations and Φ_q's rank there recorded. The reason when the loops cannot close, else "".
std::string assemble_start(const Model& m, StressScenario& s, StressResult& r) {
  if (m.constraints.empty()) return {};
  const StateAssembly a = assemble_state(m, s.q0, s.qd0);
  if (!a.assembly.status.ok) return "the initial state: " + a.assembly.status.message;
  r.equations = m.constraint_rows;
  r.rank = a.assembly.rank;
  r.redundant = a.assembly.redundant;
  return {};
}

// A motion that reaches a dead point: S λ = r has no solution there (docs/loops.md#dead-points).
StressResult dead_point_case(StressResult r, const std::string& failure) {
  r.refused = failure;
  r.verdict = std::string(kDeadPointVerdict) + ": " + failure;
  return r;
}

// The constrained equations at the (assembled) start: a failure there, or ok.
Status constrained_start(const Model& m, Workspace& ws, const StressScenario& s) {
  if (m.constraints.empty()) return {};
  LoopWorkspace lws(m);
  return constrained_forward_dynamics(m, ws, lws, s.q0, s.qd0, VecX::Zero(m.n()),
                                      Motion::kDefaultBaumgarte);
}

// Closed loops, whose stiffness changes with the posture (near a dead point most): the
// linearisation at each of the reference's samples, its largest |λ| and the smallest theory step
// of each fixed-step integrator (in `steps`, indexed as kIntegrators).
double linearize_along(const Model& m, const StressRun& ref, std::vector<double>& steps) {
  Workspace ws(m);
  double stiffest = 0;
  for (std::size_t k = 0; k < ref.q.size(); ++k) {
    const Linearization lin =
        linearize(m, ws, ref.q[k], ref.x[k].tail(m.n()), VecX::Zero(m.n()), 0);
    if (!lin.status.ok) continue;
    stiffest = std::max(stiffest, std::abs(lin.stiffest));
    for (std::size_t i = 0; i < steps.size(); ++i)
      if (const auto h = largest_stable_step(lin, kIntegrators[i]); h && std::isfinite(*h))
        steps[i] = steps[i] < 0 ? *h : std::min(steps[i], *h);
  }
  return stiffest;
}

// Conditioning along the reference (at its ends only for a large model).
void conditioning_along(const Model& m, Workspace& ws, bool large, const StressRun& ref,
                        StressResult& r) {
  r.cond_min = INFINITY;
  for (const VecX& x : large ? std::vector<VecX>{ref.x.front(), ref.x.back()} : ref.x) {
    evaluate(m, ws, x.head(m.n()), x.tail(m.n()), VecX());
    const MassMatrixHealth h = mass_matrix_health(ws.Ms);
    r.cond_min = std::min(r.cond_min, h.condition);
    r.cond_max = std::max(r.cond_max, h.condition);
    r.asymmetry = std::max(r.asymmetry, h.asymmetry);
    r.positive_definite = r.positive_definite && h.positive_definite;
  }
}

// The largest step at which `kind` stays stable, from the linear estimate 1/|λ|: bracketed by
// factors of 2 (every explicit method here is unstable beyond h |λ| = 10), then bisected on
// log h to 1 %. A trial run covers at least kMinSteps steps and kPeriods periods of the stiffest
// mode, however long or short the scenario is, and is stable when it neither diverges nor fails.
double measured_stable_step(const Model& m, const StressScenario& s, IntegratorKind kind,
                            double stiffest) {
  const double period = 2 * std::numbers::pi / stiffest;
  const auto stable = [&](double dt) {
    const double span = std::max(kPeriods * period, kMinSteps * dt);
    auto integ =
        make_integrator(m, {.kind = kind, .fixed = {.dt = dt, .max_steps = 1'000'000'000}});
    integ->reset(0, s.q0, s.qd0, span);
    return integ->advance_to(span).ok;
  };
  double lo = 1 / stiffest;
  while (!stable(lo) && lo * stiffest > 1e-6) lo /= 2;
  double hi = 2 * lo;
  while (stable(hi) && hi * stiffest < 100) hi *= 2;
  while (hi / lo > 1.01) {
    const double mid = lo * std::sqrt(hi / lo);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo;
}

// Every integrator at the scenario's step or tolerance against the reference; the fixed-step
// ones' stable limit, by theory (the linearisation at the start and along the motion) and
// measured.
void run_integrators(const Model& m, const StressScenario& s, const std::vector<double>& times,
                     const StressRun& ref, const Linearization& lin,
                     const std::vector<double>& along, double state_scale, StressResult& r) {
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
    const StressRun run = integrate(m, o, s, times, false);
    it.steps = run.stats.steps;
    if (run.status.ok) {
      it.error = max_error(run.x, ref.x) / state_scale;
      if (!m.constraints.empty()) it.max_position_residual = run.residual.position;
    } else {
      it.failure = run.status.message;
    }
    if (!is_adaptive(kind) && r.stiffest > 0) {
      if (const auto h = largest_stable_step(lin, kind); h && std::isfinite(*h))
        it.theory_step = *h;
      it.theory_step_along = along[r.integrators.size()];
      it.largest_stable_step = measured_stable_step(m, s, kind, r.stiffest);
    }
    r.integrators.push_back(std::move(it));
  }
}

// Simbody's run of the same scenario against the reference (in joint coordinates θ).
void compare_simbody(const Model& m, const StressScenario& s, const std::vector<double>& times,
                     const StressRun& ref, double state_scale, StressResult& r) {
  try {
    SimbodyTwin twin(twin_model(m));
    twin.close_loops(!m.constraints.empty());  // the constrained motion, from the assembled start
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

void give_verdict(StressResult& r, bool stiffest_dissipative) {
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
}

}  // namespace

StressResult refused_case(const std::string& why) {
  StressResult r;
  r.refused = why;
  r.verdict = "refused: " + why;
  return r;
}

StressResult run_stress(const Model& m, const StressScenario& given) {
  StressResult r;
  r.n = m.n();
  StressScenario s = given;
  if (const std::string why = assemble_start(m, s, r); !why.empty()) return refused_case(why);
  // (Closed loops: 100, along which the nearest dead point is looked for.)
  const int samples = s.large ? 2 : m.constraints.empty() ? 10 : 100;
  std::vector<double> times;
  for (int k = 1; k <= samples; ++k) times.push_back(s.t_end * k / samples);

  // The initial state must have a regular M^s.
  Workspace ws(m);
  if (const Status st = tree_forward_dynamics(m, ws, s.q0, s.qd0, VecX::Zero(m.n())); !st.ok)
    return refused_case("at the initial state: " + st.message);
  if (const Status st = constrained_start(m, ws, s); !st.ok)
    return at_dead_point(st) ? dead_point_case(r, "at the initial state: " + st.message)
                             : refused_case("at the initial state: " + st.message);
  Linearization lin;
  bool stiffest_dissipative = false;  // the stiffness bdf cures (femdyn check's rule)
  if (!s.large) {
    // Closed loops: the constrained equations without Baumgarte's pair. The fixed-step runs
    // project the state onto the loops after every step, which removes what that pair would
    // amplify, so only the mechanism's own modes limit their step (measured: a parallelogram's
    // rk4 stays stable at 4x the 2.785/20 s its pair −20 1/s would allow).
    lin = linearize(m, ws, s.q0, s.qd0, VecX::Zero(m.n()), 0);
    r.stiffest = std::abs(lin.stiffest);
    if (const std::vector<Mode> md = modes(lin, has_dampers(m)); !md.empty())
      stiffest_dissipative = md.front().dissipative();
  }

  // Reference: Dormand–Prince, or BDF when Dormand–Prince cannot (stiff).
  IntegratorOptions ref_options{
      .kind = IntegratorKind::Dopri,
      .adaptive = {.rtol = 1e-10, .atol = 1e-12, .max_steps = 200'000, .stop_at_outputs = true}};
  if (s.large) ref_options = {.kind = IntegratorKind::Rk4, .fixed = {.dt = s.dt / 2}};
  StressRun ref = integrate(m, ref_options, s, times, true);
  r.reference = s.large ? "rk4 at dt/2" : "dopri rtol 1e-10";
  // A dead point is the motion's, not a stiffness that bdf would cure.
  if (at_dead_point(ref.status)) return dead_point_case(r, ref.status.message);
  if (!ref.status.ok && !s.large) {
    ref_options.kind = IntegratorKind::Bdf;
    ref = integrate(m, ref_options, s, times, true);
    r.reference = "bdf rtol 1e-10";
  }
  if (at_dead_point(ref.status)) return dead_point_case(r, ref.status.message);
  if (!ref.status.ok)
    return refused_case("no integrator resolves the motion: " + ref.status.message);
  if (!m.constraints.empty()) {
    r.max_position_residual = ref.residual.position;
    r.max_velocity_residual = ref.residual.velocity;
    r.dead_point_ratio = INFINITY;
    for (const VecX& q : ref.q)
      r.dead_point_ratio = std::min(r.dead_point_ratio, dead_point_ratio(m, q, r.rank));
  }
  std::vector<double> along(2, -1.0);  // rk4, euler
  if (!m.constraints.empty() && !s.large) r.stiffest_along = linearize_along(m, ref, along);
  double state_scale = 1;
  for (const VecX& x : ref.x) state_scale = std::max(state_scale, x.cwiseAbs().maxCoeff());
  for (std::size_t k = 0; k < ref.balance.size(); ++k)
    r.energy_error = std::max(r.energy_error, ref.scale[k] > 0 ? ref.balance[k] / ref.scale[k] : 0);

  conditioning_along(m, ws, s.large, ref, r);

  run_integrators(m, s, times, ref, lin, along, state_scale, r);
  if (s.large)
    r.search_note =
        "no step search: the linearisation (4n evaluations and a dense eigenproblem of 2n = " +
        std::to_string(2 * m.n()) + ") takes too long at this size";
  else if (r.stiffest == 0)
    r.search_note = "no step search: no mode at the initial state (every step is stable)";

  if (s.large)
    r.simbody_note = "not run (size)";
  else
    compare_simbody(m, s, times, ref, state_scale, r);
  give_verdict(r, stiffest_dissipative);
  return r;
}

}  // namespace femdyn::validation
