#include "sim/recorded_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "core/joints/passive.hpp"

namespace femdyn {

// Joints with finite limits, checked after every step; each reported once.
class LimitWatch {
 public:
  explicit LimitWatch(const Model& m) : model_(m), ws_(m) {
    for (int j = 0; j < m.n_theta(); ++j) {
      const Joint& J = m.bodies[m.theta_joint[j]].joint;
      if (std::isfinite(J.lower) || std::isfinite(J.upper)) limited_.push_back(j);
      if (std::isfinite(J.velocity_limit)) fast_.push_back(j);
    }
  }
  template <class Q, class Qd>
  void look(double t, const Q& q, const Qd& qd, std::vector<LimitCrossing>& out,
            std::vector<VelocityExcess>& too_fast) {
    if (limited_.empty() && fast_.empty()) return;
    q_ = q;
    qd_ = qd;
    try {
      joint_state(model_, ws_, q_, qd_);
    } catch (const std::exception&) {
      return;  // a law undefined here: the integrator's next evaluation says so
    }
    for (int& j : limited_) {
      if (j < 0) continue;
      const Joint& J = model_.bodies[model_.theta_joint[j]].joint;
      const double x = ws_.theta[J.idx_q];  // (limits are on joints of one coordinate)
      if (x >= J.lower && x <= J.upper) continue;
      out.push_back({j, J.name, t, x, J.lower, J.upper});
      j = -1;  // once per joint
    }
    for (int& j : fast_) {
      if (j < 0) continue;
      const Joint& J = model_.bodies[model_.theta_joint[j]].joint;
      const double w = ws_.theta_dot[j];
      if (!(std::abs(w) > J.velocity_limit)) continue;
      too_fast.push_back({j, J.name, t, w, J.velocity_limit});
      j = -1;
    }
  }

 private:
  const Model& model_;
  Workspace ws_;
  VecX q_, qd_;
  std::vector<int> limited_, fast_;
};

RunWatch::RunWatch(Integrator& integ)
    : initial_scale_(integ.divergence().initial_scale()),
      limits_(std::make_unique<LimitWatch>(integ.motion().model())),
      saturated_before_(integ.motion().saturated_evaluations()),
      saturations_before_(integ.motion().saturations()) {
  run_.initial = integ.divergence().initial();  // E(0), as reset() evaluated it
  run_.scale = initial_scale_;
  limits_->look(integ.t(), integ.q(), integ.qd(), run_.limit_crossings, run_.velocity_excesses);
}

RunWatch::~RunWatch() = default;

void RunWatch::after_step(Integrator& integ) {
  if (integ.motion().saturated_at(integ.t())) ++run_.saturated_steps;
  limits_->look(integ.t(), integ.q(), integ.qd(), run_.limit_crossings, run_.velocity_excesses);
}

Energy RunWatch::at_row(Integrator& integ) {
  const Energy E = integ.motion().energy_at(integ.y().data());
  run_.max_balance =
      std::max(run_.max_balance, std::abs(E.total() - run_.initial.total() - integ.work()));
  run_.scale = std::max(run_.scale, initial_scale_ + std::abs(integ.work()));
  if (integ.motion().constrained()) {
    const Motion::ConstraintResidual c = integ.motion().constraint_residual(integ.y().data());
    run_.max_position_residual = std::max(run_.max_position_residual, c.position);
    run_.max_velocity_residual = std::max(run_.max_velocity_residual, c.velocity);
  }
  ++run_.rows;
  return E;
}

void RunWatch::finish(Integrator& integ) {
  const Model& model = integ.motion().model();
  run_.unapplied_effort_limits.clear();
  for (const Body& b : model.bodies)
    if (std::isfinite(b.joint.effort_limit) &&
        std::none_of(model.coordinate_joints.begin(), model.coordinate_joints.end(),
                     [&](const CoordinateJoint& c) { return &model.bodies[c.body] == &b; }))
      run_.unapplied_effort_limits.push_back(b.joint.name);
  const Motion& motion = integ.motion();
  run_.saturated_evaluations = motion.saturated_evaluations() - saturated_before_;
  run_.saturations.clear();
  for (int i = 0; i < model.n(); ++i)
    if (const long k = motion.saturations()[i] - saturations_before_[i]; k > 0)
      run_.saturations.push_back({model.coordinate_names[i], model.effort_limit[i], k});
}

RecordedRun run_recorded(Integrator& integ, double t_end, long every,
                         const std::vector<double>* times,
                         const std::function<void(const Integrator&, const Energy&)>& row,
                         const std::function<bool(double t)>& stop) {
  RunWatch watch(integ);
  RecordedRun& r = watch.run();
  if (Status plan = integ.plan(times ? (times->empty() ? integ.t() : times->back()) : t_end);
      !plan.ok) {
    r.status = plan;
    r.refused = true;
    return r;
  }
  const auto output = [&] { row(integ, watch.at_row(integ)); };
  // `stop` is also asked inside the steps (at most every 20 ms: Motion::set_interrupt), so that a
  // long adaptive step or a long span between outputs ends at once.
  const Motion::InterruptScope inside_steps(integ.motion(), [&] { return stop(integ.t()); });
  const auto interrupted = [&] {
    if (!r.status.interrupted) return false;
    r.status = {};
    return r.interrupted = true;
  };
  const auto begin = std::chrono::steady_clock::now();
  if (times) {
    for (double t : *times) {
      if (t > integ.t()) r.status = integ.advance_to(t);
      if (interrupted() || !r.status.ok) break;
      watch.after_step(integ);
      output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  } else {
    output();
    for (long step = 1; integ.t() < t_end; ++step) {
      r.status = integ.step();
      if (interrupted() || !r.status.ok) break;
      watch.after_step(integ);
      if (step % every == 0 || integ.t() >= t_end) output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  watch.finish(integ);
  return r;
}

bool conservative(const Model& model, bool driven) {
  bool c = !driven && model.torques.empty() && !model.has_rate_damping;
  for (const Body& b : model.bodies) c = c && !dissipates(b.joint);
  return c;
}

}  // namespace femdyn
