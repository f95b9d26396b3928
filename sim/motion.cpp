#include "sim/motion.hpp"

#include <cmath>
#include <cstdio>
#include <utility>

#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"

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
    const Joint& J = model.bodies[model.theta_joint[j]].joint;
    if (J.nv == 1 && dissipates(J))
      P += passive_joint_power(J, ws.theta[J.idx_q], ws.theta_dot[j]);
    else if (J.nv > 1)  // a spherical or free joint's damper on each rate
      P -= J.damping * ws.theta_dot[j] * ws.theta_dot[j];
  }
  for (int k = 0; k < model.rate_damping.outerSize(); ++k)  // the bars' −q̇ᵀ D q̇
    for (SpMat::InnerIterator it(model.rate_damping, k); it; ++it)
      P -= qd[it.row()] * it.value() * qd[it.col()];
  for (const BodyTorque& t : model.torques) P += t.torque.dot(ws.body[t.body].w);
  if (!model.springs.empty()) P += ws.spring_power;  // (of this state: forward dynamics set it)
  return P;
}

Motion::Motion(const Model& model, Actuation tau)
    : model_(model), tau_(std::move(tau)), ws_(model) {
  q_ = qd_ = u_ = VecX::Zero(model.n());
  saturations_.assign(model.n(), 0);
  flat_ = flat_model(model);
  if (!flat_) q_c_ = q_ = neutral_posture(model);
  if (!model.constraints.empty()) loops_ = std::make_unique<LoopWorkspace>(model);
}

// (Joint by joint over Model::coordinate_joints, whose addresses are their places in q and v.)
void Motion::start_chart(const VecX& q, double* y) {
  if (flat_) {
    Eigen::Map<VecX>(y, n()) = q;
    return;
  }
  q_c_ = q;
  Eigen::Map<VecX>(y, n()).setZero();
}

void Motion::configuration(const double* y, VecX& q) const {
  if (flat_) {
    q = Eigen::Map<const VecX>(y, n());
    return;
  }
  q.resize(model_.n_q());
  for (const CoordinateJoint& c : model_.coordinate_joints)
    integrate_configuration(model_.bodies[c.body].joint, q_c_.data() + c.q, y + c.v,
                            q.data() + c.q);
}

void Motion::recenter(double* y) {
  if (flat_) return;
  VecX q;
  configuration(y, q);
  q_c_ = q;
  Eigen::Map<VecX>(y, n()).setZero();
}

double Motion::chart_extent(const double* y) const {
  double extent = 0;
  if (flat_) return extent;
  for (const CoordinateJoint& c : model_.coordinate_joints)
    if (const Joint& J = model_.bodies[c.body].joint; !is_flat(J))  // its rotation: last 3 rates
      extent = std::max(extent, Eigen::Map<const Vec3>(y + c.v + J.nv - 3).norm());
  return extent;
}

void Motion::chart_rates(const double* xi, const double* v, double* xi_dot) const {
  if (flat_) {
    std::copy(v, v + n(), xi_dot);
    return;
  }
  for (const CoordinateJoint& c : model_.coordinate_joints)
    chart_rate(model_.bodies[c.body].joint, q_c_.data() + c.q, xi + c.v, v + c.v, xi_dot + c.v);
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

bool Motion::interrupt_requested() {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_interrupt_look_) return false;
  next_interrupt_look_ = now + std::chrono::milliseconds(20);
  return interrupt_();
}

Status Motion::rhs(double t, const double* y, double* ydot) {
  if (interrupt_ && interrupt_requested()) {
    Status st{false, at_time(t) + "interrupted"};
    st.interrupted = true;
    return st;
  }
  ++evaluations_;
  const int n = model_.n();
  configuration(y, q_);
  qd_ = Eigen::Map<const VecX>(y + n, n);
  if (Status st = check_state(t, y); !st.ok) return st;
  if (control_) {
    try {
      control_(t, q_, qd_, u_);
    } catch (...) {  // (no exception crosses SUNDIALS' C frames: kept, rethrown by the caller)
      control_error_ = std::current_exception();
      return {false, at_time(t) + "the controller failed", -1};
    }
    if (u_.size() != n)
      return {false,
              at_time(t) + "the controller's tau has " + std::to_string(u_.size()) +
                  " entries, expected " + std::to_string(n),
              -1};
  } else {
    requested_actuation(t, u_);
  }
  // (an input's fault, not an overflow of the motion: non_finite stays false)
  if (!u_.allFinite())
    return {false,
            at_time(t) + (control_ ? "the controller's tau is NaN or Inf"
                                   : "the actuation tau(t) is NaN or Inf"),
            -1};
  if (model_.has_effort_limits) count_saturation(u_);
  Status st = accelerations();
  if (st.ok && !model_.prescribed.empty()) st = drive_prescribed(t);
  if (!st.ok) {
    st.message = at_time(t) + st.message;
    return st;
  }
  chart_rates(y, y + n, ydot);
  Eigen::Map<VecX>(ydot + n, n) = ws_.qdd;
  ydot[2 * n] = nonconservative_power(model_, ws_, qd_, u_);
  return {};
}

Status Motion::accelerations() {
  return loops_ ? constrained_forward_dynamics(model_, ws_, *loops_, q_, qd_, u_, baumgarte_)
                : tree_forward_dynamics(model_, ws_, q_, qd_, u_);
}

// q̈ is affine in τ: q̈(u + Σ_p τ_p e_p) = q̈(u) + Σ_p τ_p M⁻¹ e_p (M⁻¹ projected onto the loops
// where there are loops), so (M⁻¹)_PP τ_P = q̈*_P − q̈_P gives the prescribed coordinates their
// q̈* exactly. Each column of M⁻¹ costs one more forward dynamics, with a unit torque added.
Status Motion::driven_actuation(double t, const double* y, const VecX& tau, VecX& out) {
  out = tau;
  if (model_.prescribed.empty()) return {};
  configuration(y, q_);
  qd_ = Eigen::Map<const VecX>(y + n(), n());
  u_ = tau;
  Status st = accelerations();
  if (st.ok) st = drive_prescribed(t);
  if (st.ok) out = u_;
  return st;
}

Status Motion::drive_prescribed(double t) {
  const std::vector<PrescribedCoordinate>& P = model_.prescribed;
  const int k = static_cast<int>(P.size());
  free_qdd_ = ws_.qdd;
  driven_cols_.resize(n(), k);
  driven_gain_.resize(k, k);
  driven_need_.resize(k);
  for (int j = 0; j < k; ++j) {
    const int c = P[j].coordinate;
    const auto [q, v, a] = P[j].motion.at(t);
    const double w = kPrescribedRate;
    driven_need_[j] = a + 2 * w * (v - qd_[c]) + w * w * (q - q_[c]) - free_qdd_[c];
    u_[c] += 1;
    if (Status st = accelerations(); !st.ok) return st;
    u_[c] -= 1;
    driven_cols_.col(j) = ws_.qdd - free_qdd_;
  }
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) driven_gain_(i, j) = driven_cols_(P[i].coordinate, j);
  if (k == 1)
    driven_need_[0] /= driven_gain_(0, 0);
  else
    driven_need_ = driven_gain_.partialPivLu().solve(driven_need_);
  if (!driven_need_.allFinite())
    return {false,
            "the torque that holds the prescribed joint '" + P[0].joint +
                "' on its motion is NaN or Inf (it moves no inertia of its own)",
            P[0].coordinate, true};
  for (int j = 0; j < k; ++j) u_[P[j].coordinate] += driven_need_[j];
  ws_.qdd = free_qdd_;
  ws_.qdd.noalias() += driven_cols_ * driven_need_;  // (no temporary: every evaluation)
  return {};
}

void Motion::drive_jacobian(const MatX& Minv, MatX& dqdd_dq, MatX& dqdd_dv) const {
  const std::vector<PrescribedCoordinate>& P = model_.prescribed;
  const int k = static_cast<int>(P.size());
  if (k == 0) return;
  const double w = kPrescribedRate;
  MatX cols(n(), k), gain(k, k), need_q(k, n()), need_v(k, n());
  for (int j = 0; j < k; ++j) {
    const int c = P[j].coordinate;
    cols.col(j) = Minv.col(c);
    need_q.row(j) = -dqdd_dq.row(c);
    need_v.row(j) = -dqdd_dv.row(c);
    need_q(j, c) -= w * w;
    need_v(j, c) -= 2 * w;
  }
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) gain(i, j) = cols(P[i].coordinate, j);
  const auto lu = gain.partialPivLu();
  dqdd_dq += cols * lu.solve(need_q);
  dqdd_dv += cols * lu.solve(need_v);
}

void Motion::requested_actuation(double t, VecX& tau) const {
  if (tau_)
    tau_(t, tau);
  else
    tau.setZero(n());
}

void Motion::tau_at(double t, const VecX& q, const VecX& v, VecX& tau) const {
  if (!control_) return actuation(t, tau);
  control_(t, q, v, tau);
  if (model_.has_effort_limits && tau.size() == n())
    tau = tau.cwiseMax(-model_.effort_limit).cwiseMin(model_.effort_limit);
}

void Motion::rethrow_control_error() {
  if (!control_error_) return;
  std::exception_ptr e = std::exchange(control_error_, nullptr);
  std::rethrow_exception(e);
}

void Motion::actuation(double t, VecX& tau) const {
  requested_actuation(t, tau);
  if (model_.has_effort_limits)
    tau = tau.cwiseMax(-model_.effort_limit).cwiseMin(model_.effort_limit);
}

bool Motion::saturated_at(double t) const {
  if (!model_.has_effort_limits) return false;
  if (control_) return last_saturated_;
  VecX tau;
  requested_actuation(t, tau);
  return (tau.cwiseAbs().array() > model_.effort_limit.array()).any();
}

// τ_i clamped to ±effort_i, each clamp counted.
void Motion::count_saturation(VecX& tau) {
  bool any = false;
  for (int i = 0; i < n(); ++i) {
    const double e = model_.effort_limit[i];
    if (!(std::abs(tau[i]) > e)) continue;
    tau[i] = std::copysign(e, tau[i]);
    ++saturations_[i];
    any = true;
  }
  last_saturated_ = any;
  if (any) ++saturated_evaluations_;
}

Status Motion::project(double t, double* y) {
  if (!loops_) return {};
  const int n = model_.n();
  configuration(y, q_);
  AssemblyOptions options;
  options.max_iterations = 10;
  options.rank = false;
  const AssemblyReport r = assemble(model_, ws_, loops_->k, q_, options);
  if (!r.status.ok) return {false, at_time(t) + r.status.message, -1};
  qd_ = Eigen::Map<const VecX>(y + n, n);
  if (Status st = project_velocity(model_, ws_, *loops_, q_, qd_); !st.ok)
    return {false, at_time(t) + st.message, -1};
  start_chart(q_, y);
  Eigen::Map<VecX>(y + n, n) = qd_;
  return {};
}

Motion::ConstraintResidual Motion::constraint_residual(const double* y) {
  if (!loops_) return {};
  const int n = model_.n();
  configuration(y, q_);
  qd_ = Eigen::Map<const VecX>(y + n, n);
  constraint_kinematics(model_, ws_, q_, qd_, loops_->k);
  loops_->r.noalias() = loops_->k.J * qd_;  // Φ_q v (r: the workspace's scratch of m)
  return {loops_->k.phi.cwiseAbs().maxCoeff(), loops_->r.cwiseAbs().maxCoeff()};
}

Energy Motion::energy_at(const double* y) {
  const int n = model_.n();
  configuration(y, q_);
  qd_ = Eigen::Map<const VecX>(y + n, n);
  return energy(model_, ws_, q_, qd_);
}

}  // namespace femdyn
