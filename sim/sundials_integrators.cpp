#include "sim/sundials_integrators.hpp"

#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/derivatives/derivatives.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/rotation.hpp"

namespace femdyn {

// One run's SUNDIALS objects; y wraps the integrator's own y_ (no copy).
struct SundialsRun {
  SUNContext ctx = nullptr;
  N_Vector y = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver LS = nullptr;
  void* arkode = nullptr;
  void* cvode = nullptr;
  ~SundialsRun() {
    if (arkode) ERKStepFree(&arkode);
    if (cvode) CVodeFree(&cvode);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (y) N_VDestroy(y);
    if (ctx) SUNContext_Free(&ctx);
  }
};

namespace {

Adaptive& self(void* user_data) { return *static_cast<Adaptive*>(user_data); }

int rhs_callback(double t, N_Vector y, N_Vector ydot, void* user_data) {
  return self(user_data).rhs(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
}

void error_handler(int, const char* module, const char* function, char* msg, void* user_data) {
  self(user_data).record(std::string(module) + "/" + function + ": " + msg);
}

int jacobian_callback(double t, N_Vector y, N_Vector fy, SUNMatrix J, void* user_data, N_Vector,
                      N_Vector, N_Vector) {
  return static_cast<Bdf*>(user_data)->jacobian(t, N_VGetArrayPointer(y), N_VGetArrayPointer(fy),
                                                SUNDenseMatrix_Data(J));
}

// Creates the context and wraps y (both methods).
void open(SundialsRun& r, VecX& y) {
  if (SUNContext_Create(nullptr, &r.ctx) != 0) throw std::runtime_error("SUNContext_Create failed");
  r.y = N_VMake_Serial(static_cast<sunindextype>(y.size()), y.data(), r.ctx);
}

}  // namespace

Adaptive::Adaptive(const Model& model, const AdaptiveOptions& options, Actuation tau)
    : Integrator(model, std::move(tau)), options_(options) {}

Adaptive::~Adaptive() = default;

int Adaptive::rhs(double t, const double* y, double* ydot) {
  Status st = motion_.rhs(t, y, ydot);
  if (st.ok) return 0;
  rhs_failure_ = std::move(st);
  return -1;  // unrecoverable: a singular M^s or a NaN is not cured by a smaller step
}

Status Adaptive::failure(int flag) {
  if (!rhs_failure_.ok) {  // f itself failed (directly, or in the Jacobian's differences)
    Status st = rhs_failure_;
    if (st.non_finite)
      st.message += "; likely cause: the state overflowed (forces or speeds beyond double range)";
    else if (st.message.find("M^s") != std::string::npos)  // (not a law's failure: says its own)
      st.message += "; likely cause: M^s lost positive definiteness along the motion";
    return st;
  }
  const std::string at = at_time(t_), h = format_short(std::abs(current_step())) + " s";
  switch (flag) {
    case CV_TOO_MUCH_WORK:
      return {false, at + "more than " + std::to_string(options_.max_steps) +
                         " steps (max_steps) before the next output, at step size " + h +
                         "; likely cause: a stiff model for an explicit method (use bdf), or "
                         "a motion too fast for the tolerances"};
    case CV_TOO_MUCH_ACC:
      return {false, at + "the tolerances cannot be met in double precision; loosen rtol/atol"};
    case CV_ERR_FAILURE:
    case CV_TOO_CLOSE:
      return {false, at + "step-size underflow: the error test failed repeatedly down to step " +
                         h +
                         "; likely cause: a singularity in the motion (M^s nearly "
                         "singular, a discontinuous actuation) or tolerances below round-off"};
    case CV_CONV_FAILURE:
    case CV_LSETUP_FAIL:
    case CV_LSOLVE_FAIL:
      return {false, at + "the Newton iteration failed to converge repeatedly down to step " + h +
                         "; likely cause: a Jacobian too poor for this stiffness, or a "
                         "singularity in the motion"};
    default:
      return {false, at + "the integrator failed (SUNDIALS flag " + std::to_string(flag) +
                         "): " + sundials_message_};
  }
}

std::string Adaptive::setting() const {
  return "rtol " + format_short(options_.rtol) + ", atol " + format_short(options_.atol);
}

Status Adaptive::plan(double t_end) {
  const double span = t_end - t_;
  if (!(span > 0)) return {};
  const double t_max = std::max(std::abs(t_), std::abs(t_end));
  if (span < kMinAdaptiveSpan || span <= 4 * std::numeric_limits<double>::epsilon() * t_max)
    return {false, "a run of " + format_short(span) + " s from t = " + format_short(t_) +
                       " s is too short for " + name() +
                       ": an adaptive integrator needs at least 1e-100 s and more than the "
                       "resolution of the time (its first step is estimated from the span); use "
                       "rk4 or euler, whose one step lands on t_end"};
  return {};
}

Status Adaptive::advance(double t_out) {
  if (!motion_.flat() || motion_.constrained()) return advance_stepwise(t_out);
  double t_reached = t_;
  const int flag = evolve(t_out, t_reached, false);
  return finish(flag, t_reached, t_out);
}

Status Adaptive::advance_stepwise(double t_out) {
  set_stop_time(std::min(t_out, t_stop_));
  while (t_ < t_out) {
    double t_reached = t_;
    const int flag = evolve(t_out, t_reached, true);
    if (Status st = finish(flag, t_reached, t_reached); !st.ok) return st;
    if (Status st = settle(std::min(t_out, t_stop_)); !st.ok) return st;
  }
  if (std::isfinite(t_stop_)) set_stop_time(t_stop_);
  return {};
}

Status Adaptive::settle(double t_stop) {
  const bool chart_far = motion_.chart_extent(y_.data()) > Motion::kChartLimit;
  const bool drifted = drifted_off_constraints();
  if (!chart_far && !drifted) return {};
  restarted_ = stats_;
  const double h = current_step();
  motion_.recenter(y_.data());
  if (drifted)
    if (Status p = motion_.project(t_, y_.data()); !p.ok) return p;
  restarting_ = true;
  start();
  restarting_ = false;
  set_initial_step(h);
  if (std::isfinite(t_stop)) set_stop_time(t_stop);
  return {};
}

// A closed loop's state that has left its constraints by more than 10 times the error the
// method is asked to keep in a step (atol + rtol |y|, on the positions and on the rates): it is
// projected back and the method restarted. (Baumgarte's term keeps the drift below that in
// the runs measured, so that restarts are rare: each costs a multistep method its history.)
bool Adaptive::drifted_off_constraints() {
  if (!motion_.constrained()) return false;
  const Motion::ConstraintResidual r = motion_.constraint_residual(y_.data());
  const int n = motion_.n();
  const double q_size = n ? y_.head(n).cwiseAbs().maxCoeff() : 0.0;
  const double v_size = n ? y_.segment(n, n).cwiseAbs().maxCoeff() : 0.0;
  return r.position > 10 * (options_.atol + options_.rtol * q_size) ||
         r.velocity > 10 * (options_.atol + options_.rtol * v_size);
}

void Adaptive::restart_method() {
  if (!run_) return;
  const double h = current_step();
  restarted_ = stats_;  // (the counters restart from 0 with the method)
  reinit();
  if (h > 0) set_initial_step(h);
  set_stop_time(t_stop_);
  rhs_failure_ = {};
}

Status Adaptive::one_step() {
  double t_reached = t_;
  const int flag = evolve(std::isfinite(t_stop_) ? t_stop_ : t_ + 1, t_reached, true);
  if (Status st = finish(flag, t_reached, t_reached); !st.ok) return st;
  return settle(t_stop_);
}

Status Adaptive::finish(int flag, double t_reached, double t_target) {
  read_stats();
  stats_.steps += restarted_.steps;
  stats_.rejected += restarted_.rejected;
  stats_.jac_evals += restarted_.jac_evals;
  stats_.rhs_evals = motion_.evaluations();
  if (flag >= 0) {  // CV_SUCCESS, CV_TSTOP_RETURN
    t_ = t_target;
    if (Status bad = motion_.check_state(t_, y_.data()); !bad.ok) return bad;
    return {};
  }
  t_ = t_reached;  // SUNDIALS returns the last good state with the time it reached
  return failure(flag);
}

// ---- Dormand–Prince (ARKODE ERKStep) ------------------------------------------------------

DormandPrince::DormandPrince(const Model& model, const AdaptiveOptions& options, Actuation tau)
    : Adaptive(model, options, std::move(tau)) {}

void DormandPrince::start() {
  if (!restarting_) restarted_ = {};  // a new run, not a restart on a moved chart
  run_ = std::make_unique<SundialsRun>();
  SundialsRun& r = *run_;
  open(r, y_);
  r.arkode = ERKStepCreate(rhs_callback, t_, r.y, r.ctx);
  if (!r.arkode) throw std::runtime_error("ERKStepCreate failed");
  ERKStepSetErrHandlerFn(r.arkode, error_handler, this);
  ERKStepSetUserData(r.arkode, this);
  ERKStepSetTableNum(r.arkode, ARKODE_DORMAND_PRINCE_7_4_5);
  ERKStepSStolerances(r.arkode, options_.rtol, options_.atol);
  ERKStepSetMaxNumSteps(r.arkode, options_.max_steps);
  if (options_.h_max > 0) ERKStepSetMaxStep(r.arkode, options_.h_max);
  if (std::isfinite(t_stop_)) ERKStepSetStopTime(r.arkode, t_stop_);
  rhs_failure_ = {};
}

void DormandPrince::reinit() { ERKStepReInit(run_->arkode, rhs_callback, t_, run_->y); }

int DormandPrince::evolve(double t_out, double& t_reached, bool one_step) {
  if (options_.stop_at_outputs && !one_step) ERKStepSetStopTime(run_->arkode, t_out);
  return ERKStepEvolve(run_->arkode, t_out, run_->y, &t_reached,
                       one_step ? ARK_ONE_STEP : ARK_NORMAL);
}

void DormandPrince::read_stats() {
  long v = 0;
  ERKStepGetNumSteps(run_->arkode, &v);
  stats_.steps = v;
  ERKStepGetNumErrTestFails(run_->arkode, &v);
  stats_.rejected = v;
}

void DormandPrince::set_stop_time(double t) { ERKStepSetStopTime(run_->arkode, t); }
void DormandPrince::set_initial_step(double h) { ERKStepSetInitStep(run_->arkode, h); }

double DormandPrince::current_step() const {
  double h = 0;
  ERKStepGetCurrentStep(run_->arkode, &h);
  return h;
}

// ---- BDF (CVODE) ---------------------------------------------------------------------------

Bdf::Bdf(const Model& model, const AdaptiveOptions& options, Actuation tau)
    : Adaptive(model, options, std::move(tau)),
      y_pert_(VecX::Zero(y_.size())),
      f_pert_(VecX::Zero(y_.size())),
      q_(VecX::Zero(model.n_q())),
      v_(VecX::Zero(model.n())),
      tau_(VecX::Zero(model.n())),
      unit_(VecX::Zero(model.n())),
      rate_plus_(VecX::Zero(model.n())),
      rate_minus_(VecX::Zero(model.n())) {
  // Once per integrator: whether the derivatives cover the model (not per Jacobian). Closed
  // loops included: f is the constrained q̈ at the run's Baumgarte rate (the projections act
  // between steps, outside f).
  if (options.analytic_jacobian && derivatives_unsupported(model).empty()) {
    derivatives_ = std::make_unique<DerivativeWorkspace>(model);
    derivative_ws_ = std::make_unique<Workspace>(model);
  }
}

Bdf::~Bdf() = default;

void Bdf::start() {
  if (!restarting_) restarted_ = {};  // a new run, not a restart on a moved chart
  run_ = std::make_unique<SundialsRun>();
  SundialsRun& r = *run_;
  open(r, y_);
  const auto N = static_cast<sunindextype>(y_.size());
  r.cvode = CVodeCreate(CV_BDF, r.ctx);
  if (!r.cvode) throw std::runtime_error("CVodeCreate failed");
  CVodeSetErrHandlerFn(r.cvode, error_handler, this);
  CVodeInit(r.cvode, rhs_callback, t_, r.y);
  CVodeSetUserData(r.cvode, this);
  CVodeSStolerances(r.cvode, options_.rtol, options_.atol);
  r.A = SUNDenseMatrix(N, N, r.ctx);
  r.LS = SUNLinSol_Dense(r.y, r.A, r.ctx);
  CVodeSetLinearSolver(r.cvode, r.LS, r.A);
  CVodeSetJacFn(r.cvode, jacobian_callback);
  // A controller's τ(q, v) is part of f, and its derivatives are not known here.
  analytic_ = derivatives_ && !motion_.controlled();
  CVodeSetMaxNumSteps(r.cvode, options_.max_steps);
  CVodeSetMaxOrd(r.cvode, options_.max_order);
  if (options_.h_max > 0) CVodeSetMaxStep(r.cvode, options_.h_max);
  if (std::isfinite(t_stop_)) CVodeSetStopTime(r.cvode, t_stop_);
  rhs_failure_ = {};
}

int Bdf::jacobian(double t, const double* y, const double* fy, double* J) {
  return analytic_ ? analytic_jacobian(t, y, J) : difference_jacobian(t, y, fy, J);
}

// f = (ξ̇, v̇, P) at y = (ξ, v, W), J = ∂f/∂y:
//   ∂ξ̇/∂(ξ, v) from the chart (chart_rows), ∂v̇/∂v = ∂q̈/∂v, ∂v̇/∂ξ = ∂q̈/∂q T(ξ)
// (chart_columns), ∂f/∂W = 0. The row of P = q̇ᵀτ + Σ P_j + Σ τ_b·ω_b is left 0: W is a
// quadrature, fed by the other rows and feeding none, so Newton's W lags by one iteration.
int Bdf::analytic_jacobian(double t, const double* y, double* J) {
  const int n = motion_.n(), N = 2 * n + 1;
  Eigen::Map<MatX> Jm(J, N, N);  // column-major, as SUNDIALS' dense matrix
  Jm.setZero();
  motion_.configuration(y, q_);
  v_ = Eigen::Map<const VecX>(y + n, n);
  motion_.actuation(t, tau_);  // τ(t), saturated as f applies it (no controller here)
  derivatives_->baumgarte = motion_.baumgarte();  // (closed loops: the rate f is integrated at)
  const Status st =
      forward_dynamics_derivatives(motion_.model(), *derivative_ws_, *derivatives_, q_, v_, tau_);
  if (!st.ok) {
    rhs_failure_ = st;
    rhs_failure_.message = at_time(t) + st.message;
    return -1;
  }
  Jm.block(n, 0, n, n) = derivatives_->dqdd_dq;
  Jm.block(n, n, n, n) = derivatives_->dqdd_dv;
  chart_rows(y, J);
  chart_columns(y, J);
  return 0;
}

int Bdf::difference_jacobian(double t, const double* y, const double* fy, double* J) {
  const int n = motion_.n(), N = 2 * n + 1;
  Eigen::Map<MatX> Jm(J, N, N);
  Jm.setZero();
  chart_rows(y, J);
  const Eigen::Map<const VecX> y0(y, N), f0(fy, N);
  y_pert_ = y0;
  // Columns of q and q̇: forward differences of (q̈, P_nc); W moves nothing (its column is 0).
  for (int j = 0; j < 2 * n; ++j) {
    const double delta = 1.5e-8 * std::max(1.0, std::abs(y0[j]));
    y_pert_[j] = y0[j] + delta;
    if (rhs(t, y_pert_.data(), f_pert_.data()) != 0) return -1;
    Jm.col(j).tail(n + 1) = (f_pert_.tail(n + 1) - f0.tail(n + 1)) / delta;
    y_pert_[j] = y0[j];
  }
  return 0;
}

// The top rows, ∂ξ̇/∂(ξ, v) of the chart rate ξ̇ = g(ξ, v) (Motion::chart_rates): [0, 1] when
// every joint is flat. Otherwise g is linear in v, so ∂g/∂v_j = g(ξ, e_j); ∂g/∂ξ_j by central
// differences of g (O(joints) each, no dynamics; smooth, so a step of 1e-6 leaves ~1e-12).
void Bdf::chart_rows(const double* y, double* J) {
  const int n = motion_.n(), N = 2 * n + 1;
  Eigen::Map<MatX> Jm(J, N, N);
  if (motion_.flat()) {
    for (int i = 0; i < n; ++i) Jm(i, n + i) = 1;
    return;
  }
  constexpr double h = 1e-6;
  y_pert_.head(n) = Eigen::Map<const VecX>(y, n);
  unit_.setZero();
  for (int j = 0; j < n; ++j) {
    unit_[j] = 1;
    motion_.chart_rates(y, unit_.data(), rate_plus_.data());
    Jm.block(0, n + j, n, 1) = rate_plus_;
    unit_[j] = 0;
    const double xj = y_pert_[j];
    y_pert_[j] = xj + h;
    motion_.chart_rates(y_pert_.data(), y + n, rate_plus_.data());
    y_pert_[j] = xj - h;
    motion_.chart_rates(y_pert_.data(), y + n, rate_minus_.data());
    y_pert_[j] = xj;
    Jm.block(0, j, n, 1) = (rate_plus_ - rate_minus_) / (2 * h);
  }
}

// ∂v̇/∂ξ in the chart around q_c from ∂q̈/∂q along the tangent at q = q_c ⊕ ξ (the derivatives'
// convention): q_c ⊕ (ξ + dξ) = q ⊕ T(ξ) dξ to first order, per manifold joint
//   rotation:  q_c ⊗ exp(ξ_r + dξ_r) = q ⊗ exp(J_r(ξ_r) dξ_r),                T_r = J_r(ξ_r);
//   position (free):  p_c + R_c (ξ_p + dξ_p) = p + R exp(ξ_r)ᵀ dξ_p,          T_p = exp(ξ_r)ᵀ;
// so the joint's columns of the rows of v̇ are ∂q̈/∂q T. Nothing on flat joints (T = 1).
void Bdf::chart_columns(const double* y, double* J) {
  if (motion_.flat()) return;
  const Model& m = motion_.model();
  const int n = motion_.n(), N = 2 * n + 1;
  Eigen::Map<MatX> Jm(J, N, N);
  const MatX& dq = derivatives_->dqdd_dq;
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& joint = m.bodies[c.body].joint;
    if (is_flat(joint)) continue;
    const int r = c.v + joint.nv - 3;  // the rotation's rates: the joint's last three
    const Vec3 xi(y[r], y[r + 1], y[r + 2]);
    Mat3 Jr_inv;
    for (int k = 0; k < 3; ++k) Jr_inv.col(k) = inverse_right_jacobian_times(xi, Vec3::Unit(k));
    Jm.block(n, r, n, 3).noalias() = dq.middleCols(r, 3) * Jr_inv.inverse();
    if (joint.nv == 6) {  // free: the position's rates first
      const double angle = xi.norm();
      const Mat3 E = angle > 0 ? axis_rotation(xi / angle, angle) : Mat3::Identity();
      Jm.block(n, c.v, n, 3).noalias() = dq.middleCols(c.v, 3) * E.transpose();
    }
  }
}

void Bdf::reinit() { CVodeReInit(run_->cvode, t_, run_->y); }

int Bdf::evolve(double t_out, double& t_reached, bool one_step) {
  if (options_.stop_at_outputs && !one_step) CVodeSetStopTime(run_->cvode, t_out);
  return CVode(run_->cvode, t_out, run_->y, &t_reached, one_step ? CV_ONE_STEP : CV_NORMAL);
}

void Bdf::read_stats() {
  long v = 0, w = 0;
  CVodeGetNumSteps(run_->cvode, &v);
  stats_.steps = v;
  CVodeGetNumErrTestFails(run_->cvode, &v);
  CVodeGetNumNonlinSolvConvFails(run_->cvode, &w);
  stats_.rejected = v + w;
  CVodeGetNumJacEvals(run_->cvode, &v);
  stats_.jac_evals = v;
}

void Bdf::set_stop_time(double t) { CVodeSetStopTime(run_->cvode, t); }
void Bdf::set_initial_step(double h) { CVodeSetInitStep(run_->cvode, h); }

double Bdf::current_step() const {
  double h = 0;
  CVodeGetCurrentStep(run_->cvode, &h);
  return h;
}

}  // namespace femdyn
