#include "sim/step_trial.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace femdyn {
namespace {

constexpr int kSamples = 20;

// The states (q, q̇) at the sample times, or a failed Status.
Status sample_run(const Model& m, const IntegratorOptions& o, const VecX& q0, const VecX& qd0,
                  double horizon, std::vector<VecX>& x) {
  auto integ = make_integrator(m, o);
  integ->reset(0, q0, qd0, horizon);
  x.clear();
  for (int k = 1; k <= kSamples; ++k) {
    if (Status st = integ->advance_to(horizon * k / kSamples); !st.ok) return st;
    x.push_back(integ->y().head(2 * m.n()));
  }
  return {};
}

}  // namespace

StepTrial try_fixed_step(const Model& m, IntegratorKind kind, double dt, const VecX& q0,
                         const VecX& qd0, const StepTrialOptions& o) {
  StepTrial t;
  t.horizon = o.horizon > 0 ? o.horizon : std::min(o.periods * o.period, 10.0);
  t.dt = dt;
  std::vector<VecX> ref, x;
  const IntegratorOptions reference{
      .kind = IntegratorKind::Dopri,
      .adaptive = {.rtol = 1e-10, .atol = 1e-10, .max_steps = 1'000'000, .stop_at_outputs = true}};
  if (Status st = sample_run(m, reference, q0, qd0, t.horizon, ref); !st.ok) {
    t.failure = "the reference run (dopri at rtol 1e-10) failed: " + st.message;
    t.reference_failed = true;
    return t;
  }
  double scale = 1;
  for (const VecX& r : ref) scale = std::max(scale, r.cwiseAbs().maxCoeff());
  long spent = 0;
  for (int k = 0; k <= o.max_halvings; ++k) {
    const double step = dt / std::pow(2.0, k);
    const long steps = std::lround(std::ceil(t.horizon / step));
    if (spent + steps > o.step_budget) break;
    spent += steps;
    t.dt = step, t.halvings = k;
    t.error_per_period = t.error = NAN;
    if (!sample_run(m, {.kind = kind, .fixed = {.dt = step}}, q0, qd0, t.horizon, x).ok) continue;
    double e = 0;
    for (std::size_t i = 0; i < ref.size(); ++i)
      e = std::max(e, (x[i] - ref[i]).cwiseAbs().maxCoeff());
    t.error = e / scale;
    t.error_per_period = t.error / (t.horizon / o.period);
    if (t.error_per_period <= o.allowed) {
      t.verified = true;
      return t;
    }
  }
  t.failure = "no step down to " + format_short(t.dt) + " s kept the error per period within " +
              format_short(o.allowed) + " over " + format_short(t.horizon) +
              " s of the model's own motion (the trial's budget: " + std::to_string(o.step_budget) +
              " steps)";
  return t;
}

}  // namespace femdyn
