#include "sim/recorded_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>

#include "core/joints/passive.hpp"

namespace femdyn {

namespace {

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

}  // namespace

RecordedRun run_recorded(Integrator& integ, double t_end, long every,
                         const std::vector<double>* times,
                         const std::function<void(const Integrator&, const Energy&)>& row,
                         const std::function<bool(double t)>& stop) {
  RecordedRun r;
  r.initial = integ.divergence().initial();  // E(0), as reset() evaluated it
  const double S0 = integ.divergence().initial_scale();
  r.scale = S0;
  if (Status plan = integ.plan(times ? (times->empty() ? integ.t() : times->back()) : t_end);
      !plan.ok) {
    r.status = plan;
    r.refused = true;
    return r;
  }
  const Model& model = integ.motion().model();
  LimitWatch limits(model);
  limits.look(integ.t(), integ.q(), integ.qd(), r.limit_crossings, r.velocity_excesses);
  const auto output = [&] {
    const Energy E = integ.motion().energy_at(integ.y().data());
    r.max_balance = std::max(r.max_balance, std::abs(E.total() - r.initial.total() - integ.work()));
    r.scale = std::max(r.scale, S0 + std::abs(integ.work()));
    if (integ.motion().constrained()) {
      const Motion::ConstraintResidual c = integ.motion().constraint_residual(integ.y().data());
      r.max_position_residual = std::max(r.max_position_residual, c.position);
      r.max_velocity_residual = std::max(r.max_velocity_residual, c.velocity);
    }
    row(integ, E);
    ++r.rows;
  };
  const auto begin = std::chrono::steady_clock::now();
  if (times) {
    for (double t : *times) {
      if (t > integ.t()) r.status = integ.advance_to(t);
      if (!r.status.ok) break;
      if (integ.motion().saturated_at(integ.t())) ++r.saturated_steps;
      limits.look(integ.t(), integ.q(), integ.qd(), r.limit_crossings, r.velocity_excesses);
      output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  } else {
    output();
    for (long step = 1; integ.t() < t_end; ++step) {
      r.status = integ.step();
      if (!r.status.ok) break;
      if (integ.motion().saturated_at(integ.t())) ++r.saturated_steps;
      limits.look(integ.t(), integ.q(), integ.qd(), r.limit_crossings, r.velocity_excesses);
      if (step % every == 0 || integ.t() >= t_end) output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  for (const Body& b : model.bodies)
    if (std::isfinite(b.joint.effort_limit) &&
        std::none_of(model.coordinate_joints.begin(), model.coordinate_joints.end(),
                     [&](const CoordinateJoint& c) { return &model.bodies[c.body] == &b; }))
      r.unapplied_effort_limits.push_back(b.joint.name);
  const Motion& motion = integ.motion();
  r.saturated_evaluations = motion.saturated_evaluations();
  for (int i = 0; i < model.n(); ++i)
    if (motion.saturations()[i] > 0)
      r.saturations.push_back(
          {model.coordinate_names[i], model.effort_limit[i], motion.saturations()[i]});
  return r;
}

bool conservative(const Model& model, bool driven) {
  bool c = !driven && model.torques.empty();
  for (const Body& b : model.bodies) c = c && !dissipates(b.joint);
  return c;
}

}  // namespace femdyn
