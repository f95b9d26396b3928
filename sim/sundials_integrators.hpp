// Adaptive integrators from SUNDIALS 6.4 (sim/integrator.hpp):
//   DormandPrince  ARKODE ERKStep with the Dormand–Prince 7-stage 5(4) table (first same as
//                  last), local error control on y, Hermite dense output at t_out.
//   Bdf            CVODE variable-order BDF (1–5) with CVODE's Newton iteration and a dense
//                  direct linear solver; the Jacobian of f is
//                    ∂f/∂y = [[0, I, 0], [∂q̈/∂q, ∂q̈/∂q̇, 0], [∂P/∂q, ∂P/∂q̇, 0]]
//                  in the state's chart (q is ξ on a manifold joint, Motion): analytic
//                  where core/derivatives/derivatives.hpp covers the model and τ does not depend on
//                  the state (decided per run, at start), with the rows of ∂P omitted; otherwise
//                  the lower rows by forward differences of forward dynamics (2n evaluations).
//                  Buffers owned here.
// The SUNDIALS memory is created by reset() (per run, not per step); SUNDIALS' own messages are
// captured and folded into the Status, never printed.
#pragma once
#include <string>

#include "sim/integrator.hpp"

namespace femdyn {

// SUNDIALS handles owned by an adaptive integrator (opaque here: the SUNDIALS headers stay in
// the .cpp).
struct SundialsRun;
struct DerivativeWorkspace;

// The shortest run an adaptive integrator takes (s): SUNDIALS' first-step estimate divides by
// the span squared, which overflows double precision below about 1e-154 s; the bound mirrors
// kMaxMagnitude (core/model/limits.hpp) as its reciprocal.
inline constexpr double kMinAdaptiveSpan = 1e-100;

class Adaptive : public Integrator {
 public:
  ~Adaptive() override;

 protected:
  Adaptive(const Model& model, const AdaptiveOptions& options, Actuation tau);
  Status advance(double t_out) override;
  Status one_step() override;
  std::string setting() const override;
  Status plan(double t_end) override;  // a span SUNDIALS cannot start on, refused
  void restart_method() override;      // reinit at (t_, y_), the last step as the first
  virtual void reinit() = 0;           // ERKStepReInit / CVodeReInit at (t_, y_)
  Status finish(int flag, double t_reached, double t_target);
  // What SUNDIALS' return code means for the user, with the step size where it failed.
  Status failure(int flag);
  // One call to ARKODE / CVODE: to t_out (dense output), or one internal step.
  virtual int evolve(double t_out, double& t_reached, bool one_step) = 0;
  virtual void read_stats() = 0;
  virtual double current_step() const = 0;
  // Never step past t (ARKODE's / CVODE's stop time), and the first step of a restarted run.
  virtual void set_stop_time(double t) = 0;
  virtual void set_initial_step(double h) = 0;
  // On a manifold (Motion::flat() false) or with closed loops: steps to t_out one at a time, and
  // restarts the method where the chart moved (a rotation in it past Motion::kChartLimit) or
  // where the state was projected back onto the constraints (drifted_off_constraints).
  Status advance_stepwise(double t_out);
  bool drifted_off_constraints();
  // After an accepted step: the chart moved or the state projected, and the method restarted
  // (never past t_stop), where either is due.
  Status settle(double t_stop);

 public:                                             // reached from the C callbacks
  int rhs(double t, const double* y, double* ydot);  // 0, or < 0 after recording rhs_failure_
  void record(const std::string& sundials_message) { sundials_message_ = sundials_message; }

 protected:
  AdaptiveOptions options_;
  std::unique_ptr<SundialsRun> run_;
  Status rhs_failure_;            // the last failed evaluation of f
  std::string sundials_message_;  // the last message SUNDIALS sent to its error handler
  IntegratorStats restarted_;     // the statistics of the runs before the last restart
  bool restarting_ = false;
};

class DormandPrince final : public Adaptive {
 public:
  DormandPrince(const Model& model, const AdaptiveOptions& options, Actuation tau = {});
  IntegratorKind kind() const override { return IntegratorKind::Dopri; }

 private:
  void start() override;
  void reinit() override;
  int evolve(double t_out, double& t_reached, bool one_step) override;
  void read_stats() override;
  double current_step() const override;
  void set_stop_time(double t) override;
  void set_initial_step(double h) override;
};

class Bdf final : public Adaptive {
 public:
  Bdf(const Model& model, const AdaptiveOptions& options, Actuation tau = {});
  ~Bdf() override;
  IntegratorKind kind() const override { return IntegratorKind::Bdf; }
  // ∂f/∂y into the column-major (2n+1)² array J at y, f(y) = fy given: analytic_jacobian or
  // difference_jacobian, as chosen for the run. 0, or −1 after recording the failure.
  int jacobian(double t, const double* y, const double* fy, double* J);
  // Whether this run's Jacobian is analytic (set by reset).
  bool analytic() const { return analytic_; }
  // The rows of (ξ̇, v̇) from the derivatives of forward dynamics at (t, y); the row of P is 0.
  // Requires a model the derivatives cover.
  int analytic_jacobian(double t, const double* y, double* J);
  // The rows of v̇ and P by forward differences of f (2n evaluations).
  int difference_jacobian(double t, const double* y, const double* fy, double* J);

 private:
  void chart_rows(const double* y, double* J);
  void chart_columns(const double* xi, double* J);
  void start() override;
  void reinit() override;
  int evolve(double t_out, double& t_reached, bool one_step) override;
  void read_stats() override;
  double current_step() const override;
  void set_stop_time(double t) override;
  void set_initial_step(double h) override;
  VecX y_pert_, f_pert_;  // Jacobian buffers
  // The derivatives, when they cover the model: their workspace and buffers for q, v, τ.
  std::unique_ptr<DerivativeWorkspace> derivatives_;
  std::unique_ptr<Workspace> derivative_ws_;
  VecX q_, v_, tau_, unit_, rate_plus_, rate_minus_;
  bool analytic_ = false;
};

}  // namespace femdyn
