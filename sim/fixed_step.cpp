#include "sim/fixed_step.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>

namespace femdyn {

FixedStep::FixedStep(const Model& model, const FixedStepOptions& options, Actuation tau)
    : Integrator(model, std::move(tau)), options_(options), y_next_(y_.size()) {}

std::string FixedStep::setting() const { return "dt = " + format_short(options_.dt) + " s"; }

Status FixedStep::one_step() {
  // The next grid time, or t_stop when it is nearer (or within round-off of the grid time).
  const double next = grid(k_ + 1);
  return advance(next >= t_stop_ - 1e-9 * options_.dt ? t_stop_ : next);
}

Status FixedStep::advance(double t_out) {
  const double dt = options_.dt;
  while (t_ < t_out) {
    if (stats_.steps >= options_.max_steps)
      return {false, at_time(t_) + "more than " + std::to_string(options_.max_steps) +
                         " steps (max_steps); likely cause: dt too small for the time span"};
    // The next grid time, unless t_out comes first; a grid time within 1e-9 dt of t_out (by
    // round-off) is t_out itself.
    double t_next = grid(k_ + 1);
    bool on_grid = true;
    if (t_next > t_out - 1e-9 * dt) {
      on_grid = t_next <= t_out + 1e-9 * dt;
      t_next = t_out;
    }
    Status st = take_step(t_next - t_);
    stats_.rhs_evals = motion_.evaluations();
    // An overflow inside the step or in the state it made (y_ itself is finite): the step
    // blew the state up, whatever the last good state shows.
    if (!st.ok) return st.non_finite ? diverged() : explain(std::move(st));
    if (!motion_.check_state(t_next, y_next_.data()).ok) return diverged();
    y_.swap(y_next_);
    motion_.recenter(y_.data());  // (a manifold's chart follows every step)
    if (motion_.constrained())    // (and closed loops their constraints: no drift kept)
      if (Status p = motion_.project(t_next, y_.data()); !p.ok) return explain(std::move(p));
    t_ = t_next;
    if (on_grid) ++k_;
    ++stats_.steps;
    if (Status w = watch(); !w.ok) return w;
  }
  return {};
}

Status FixedStep::plan(double t_end) {
  const double dt = options_.dt, span = t_end - t_;
  if (!(span > 0)) return {};
  // t + dt must differ from t at every time of the run.
  const double t_max = std::max(std::abs(t_), std::abs(t_end));
  if (t_max + dt == t_max || t_max - dt == t_max)
    return {false, "dt = " + format_short(dt) + " s is below the resolution of the time at t = " +
                       format_short(t_max) + " s (t + dt == t in double precision)"};
  const double steps = std::ceil(span / dt - 1e-9);
  if (steps <= static_cast<double>(options_.max_steps)) return {};
  // The time it would take, from a few evaluations at the start.
  VecX f(y_.size());
  const auto begin = std::chrono::steady_clock::now();
  constexpr int kProbe = 8;
  for (int i = 0; i < kProbe; ++i) (void)motion_.rhs(t_, y_.data(), f.data());
  const double per_eval =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count() / kProbe;
  const double evals = steps * evaluations_per_step();
  return {false, "the run needs " + format_short(steps) + " steps of dt = " + format_short(dt) +
                     " s over " + format_short(span) + " s (" + format_short(evals) +
                     " evaluations of forward dynamics, about " +
                     format_duration(evals * per_eval) + "), more than the limit of " +
                     std::to_string(options_.max_steps) +
                     " steps: use a larger dt, or an adaptive integrator (dopri), or raise the "
                     "limit (--max-steps, max_steps=)"};
}

Rk4::Rk4(const Model& model, const FixedStepOptions& options, Actuation tau)
    : FixedStep(model, options, std::move(tau)), stage_(y_.size()) {
  for (VecX& k : k_) k = VecX::Zero(y_.size());
}

Status Rk4::take_step(double h) {
  static constexpr double c[4] = {0, 0.5, 0.5, 1};
  for (int i = 0; i < 4; ++i) {
    if (i == 0)
      stage_ = y_;
    else
      stage_ = y_ + (c[i] * h) * k_[i - 1];
    if (Status st = motion_.rhs(t_ + c[i] * h, stage_.data(), k_[i].data()); !st.ok) return st;
  }
  y_next_ = y_ + (h / 6) * (k_[0] + 2 * k_[1] + 2 * k_[2] + k_[3]);
  return {};
}

SymplecticEuler::SymplecticEuler(const Model& model, const FixedStepOptions& options, Actuation tau)
    : FixedStep(model, options, std::move(tau)), f_(VecX::Zero(y_.size())) {}

Status SymplecticEuler::take_step(double h) {
  const int n = motion_.n();
  if (Status st = motion_.rhs(t_, y_.data(), f_.data()); !st.ok) return st;
  y_next_.segment(n, n) = y_.segment(n, n) + h * f_.segment(n, n);     // q̇ first
  motion_.chart_rates(y_.data(), y_next_.data() + n, y_next_.data());  // then q with the new q̇
  y_next_.head(n) = y_.head(n) + h * y_next_.head(n);
  y_next_[2 * n] = y_[2 * n] + h * f_[2 * n];
  return {};
}

}  // namespace femdyn
