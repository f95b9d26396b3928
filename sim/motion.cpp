#include "sim/motion.hpp"

#include <cmath>
#include <cstdio>

namespace femdyn {

std::string at_time(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "at t = %.9g s: ", t);
  return buf;
}

double nonconservative_power(const Model& model, const Workspace& ws, const VecX& qd,
                             const VecX& tau) {
  if (qd.isZero(0)) return 0;  // at rest nothing does work (and ω, θ̇ were not propagated)
  double P = tau.size() == qd.size() ? qd.dot(tau) : 0.0;
  for (int j = 0; j < model.n_theta(); ++j) {
    const double c = model.bodies[model.theta_joint[j]].joint.damping;
    if (c != 0) P -= c * ws.theta_dot[j] * ws.theta_dot[j];
  }
  for (const BodyTorque& t : model.torques) P += t.torque.dot(ws.body[t.body].w);
  return P;
}

Motion::Motion(const Model& model, Actuation tau)
    : model_(model), tau_(std::move(tau)), ws_(model) {
  q_ = qd_ = u_ = VecX::Zero(model.n());
}

Status Motion::check_state(double t, const double* y) const {
  const int n = model_.n();
  for (int i = 0; i < 2 * n + 1; ++i) {
    if (std::isfinite(y[i])) continue;
    const std::string what = i < n       ? "q_" + model_.coordinate_names[i]
                             : i < 2 * n ? "qd_" + model_.coordinate_names[i - n]
                                         : std::string("W (work of the non-conservative forces)");
    return {false, at_time(t) + "NaN or Inf in the state (" + what + ")", i < 2 * n ? i % n : -1,
            true};
  }
  return {};
}

Status Motion::rhs(double t, const double* y, double* ydot) {
  ++evaluations_;
  const int n = model_.n();
  q_ = Eigen::Map<const VecX>(y, n);
  qd_ = Eigen::Map<const VecX>(y + n, n);
  actuation(t, u_);
  if (Status st = check_state(t, y); !st.ok) return st;
  // (an input's fault, not an overflow of the motion: non_finite stays false)
  if (!u_.allFinite()) return {false, at_time(t) + "the actuation tau(t) is NaN or Inf", -1};
  Status st = forward_dynamics(model_, ws_, q_, qd_, u_);
  if (!st.ok) {
    st.message = at_time(t) + st.message;
    return st;
  }
  Eigen::Map<VecX>(ydot, n) = qd_;
  Eigen::Map<VecX>(ydot + n, n) = ws_.qdd;
  ydot[2 * n] = nonconservative_power(model_, ws_, qd_, u_);
  return {};
}

void Motion::actuation(double t, VecX& tau) const {
  if (tau_)
    tau_(t, tau);
  else
    tau.setZero(n());
}

Energy Motion::energy_at(const double* y) {
  const int n = model_.n();
  q_ = Eigen::Map<const VecX>(y, n);
  qd_ = Eigen::Map<const VecX>(y + n, n);
  return energy(model_, ws_, q_, qd_);
}

}  // namespace femdyn
