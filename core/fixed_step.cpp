#include "core/fixed_step.hpp"

#include <cstdio>

namespace femdyn {
namespace {

// The likely cause of a NaN that a fixed step produced.
Status unstable(Status st, double dt) {
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "; likely cause: the step dt = %g s is beyond the stability limit of the "
                "stiffest mode (use a smaller step, or the bdf integrator)",
                dt);
  st.message += buf;
  return st;
}

}  // namespace

FixedStep::FixedStep(const Model& model, const FixedStepOptions& options, Actuation tau)
    : Integrator(model, std::move(tau)), options_(options), y_next_(y_.size()) {}

Status FixedStep::advance(double t_out) {
  const double dt = options_.dt;
  while (t_ < t_out) {
    if (stats_.steps >= options_.max_steps)
      return {false, at_time(t_) + "more than " + std::to_string(options_.max_steps) +
                         " steps (max_steps); likely cause: dt too small for the time span"};
    // Land on t_out: the last step is shortened (or stretched by round-off, at most 1e-9 dt).
    const bool last = t_out - t_ <= dt * (1 + 1e-9);
    const double h = last ? t_out - t_ : dt;
    Status st = take_step(h);
    stats_.rhs_evals = motion_.evaluations();
    if (!st.ok) {
      // A NaN met inside the step came from the step itself: say so.
      if (st.non_finite) st = unstable(std::move(st), dt);
      return st;
    }
    if (Status bad = motion_.check_state(t_ + h, y_next_.data()); !bad.ok)
      return unstable(std::move(bad), dt);
    y_.swap(y_next_);
    t_ = last ? t_out : t_ + dt;
    ++stats_.steps;
  }
  return {};
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
  y_next_.segment(n, n) = y_.segment(n, n) + h * f_.segment(n, n);  // q̇ first
  y_next_.head(n) = y_.head(n) + h * y_next_.segment(n, n);         // then q with the new q̇
  y_next_[2 * n] = y_[2 * n] + h * f_[2 * n];
  return {};
}

}  // namespace femdyn
