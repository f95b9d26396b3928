// The equations of motion as a first-order system, the right-hand side every integrator drives
// (sim/integrator.hpp):
//
//   y = (q, q̇, W),   ẏ = f(t, y) = (q̇,  q̈ = (M^s)⁻¹ (Q(q, q̇, τ(t)) − h(q, q̇)),  P_nc),
//
// where τ(t) is a prescribed Actuation or a controller's τ = u(t, q, v) (Control; the modes in
// which one runs, and what they do to the error control, in sim/control_loop.hpp),
// for a model whose coordinates form a vector space (every joint flat: q̇ = v). With a spherical
// or free joint (nq ≠ nv) q lives on a manifold, and y holds chart coordinates instead:
//
//   y = (ξ, v, W),   q = q_c ⊕ ξ,   ξ̇ = chart rate (core/joints/kernel.hpp), v̇ = (M^s)⁻¹ (Q − h),
//
// around a chart centre q_c that the integrators move to the current q (recenter) after every
// fixed step, and whenever a rotation in ξ passes kChartLimit for the adaptive ones. Quaternions
// are therefore advanced by the exponential map and stay of norm 1 to round-off.
//
// with W the work done by the non-conservative forces (actuation τ saturated at the joints'
// effort limits, joint dampers, Coulomb friction and stop dissipation, body torques)
// and P_nc its power, so that E(t) − E(0) = W(t) for the mechanical energy E of
// core/dynamics/equations.hpp (docs/simulation.md). Every evaluation goes through forward_dynamics
// and is checked: a singular or indefinite M^s, or a NaN/Inf in q̈, is a failed Status naming the
// time, the quantity and the coordinate, never a NaN handed on.
#pragma once
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <vector>

#include "core/dynamics/equations.hpp"
#include "core/loops/constrained_dynamics.hpp"

namespace femdyn {

// τ(t) on the generalized coordinates. An empty Actuation is the passive motion (τ = 0).
using Actuation = std::function<void(double t, VecX& tau)>;
// A controller in the loop, τ = u(t, q, v): q the configuration (n_q entries, Motion::
// configuration of y), v the rates (n), τ (n, sized by the caller: write it in place). Given to a
// Motion it replaces the Actuation and is part of f (sim/control_loop.hpp for the modes). It may
// throw: rhs then fails and keeps the exception for rethrow_control_error().
using Control = std::function<void(double t, const VecX& q, const VecX& v, VecX& tau)>;

class Motion {
 public:
  Motion(const Model& model, Actuation tau = {});
  // τ = u(t, q, v) from now on (an empty u: back to the Actuation).
  void set_control(Control u) { control_ = std::move(u); }
  bool controlled() const { return static_cast<bool>(control_); }
  // Asked at most every 20 ms of wall time, before an evaluation of f: true stops the run there
  // (a Status with `interrupted`), so that Ctrl-C ends even one long adaptive step or Newton
  // iteration at once. Empty: never asked.
  void set_interrupt(std::function<bool()> requested) {
    interrupt_ = std::move(requested);
    next_interrupt_look_ = {};
  }
  // set_interrupt for a scope: the request asked while it lives, none after, however it ends.
  class InterruptScope {
   public:
    InterruptScope(Motion& motion, std::function<bool()> requested) : motion_(motion) {
      motion_.set_interrupt(std::move(requested));
    }
    ~InterruptScope() { motion_.set_interrupt({}); }
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;

   private:
    Motion& motion_;
  };

  const Model& model() const { return model_; }
  int n() const { return model_.n(); }
  int size() const { return 2 * model_.n() + 1; }  // dim y
  // Whether y holds q itself (every joint flat) rather than chart coordinates around q_c.
  bool flat() const { return flat_; }
  // y's configuration part for q (the chart then centred on q); q of the configuration at y.
  void start_chart(const VecX& q, double* y);
  void configuration(const double* y, VecX& q) const;
  // Moves the chart centre to the configuration at y (ξ = 0 after); nothing when flat.
  void recenter(double* y);
  // The largest rotation angle in y's chart coordinates (0 when flat).
  double chart_extent(const double* y) const;
  // ξ̇ at (ξ, v): v when flat.
  void chart_rates(const double* xi, const double* v, double* xi_dot) const;
  static constexpr double kChartLimit = 1.0;  // rad

  // Loops closed by constraints (core/loops/): q̈ from the constrained equations with Baumgarte's
  // rate ω (1/s), and the projection of a state back onto Φ = 0, Φ_q v = 0.
  bool constrained() const { return static_cast<bool>(loops_); }
  void set_baumgarte(double omega) { baumgarte_ = omega; }
  double baumgarte() const { return baumgarte_; }
  static constexpr double kDefaultBaumgarte = femdyn::kDefaultBaumgarte;  // 1/s
  // The state at y moved onto the constraints: q by Newton's least-norm steps, v by the
  // kinetic-energy projection (core/loops/assembly.hpp). Fails when the loops cannot close.
  Status project(double t, double* y);
  // |Φ(q)|∞ and |Φ_q v|∞ at y (0 without constraints).
  struct ConstraintResidual {
    double position = 0, velocity = 0;
  };
  ConstraintResidual constraint_residual(const double* y);
  // λ of the last evaluation (constrained only).
  const VecX& multipliers() const { return loops_->lambda; }

  // ẏ = f(t, y) into ydot (both of size(); may be SUNDIALS' arrays). Counts the evaluation.
  Status rhs(double t, const double* y, double* ydot);
  long evaluations() const { return evaluations_; }
  // The τ the last rhs applied: the actuation (or the controller's), with the prescribed
  // coordinates' driving torques.
  const VecX& applied_actuation() const { return u_; }
  // τ as the dynamics applies it at (t, y) under the actuation `tau`: `tau` with the prescribed
  // coordinates' driving torques τ_P added (Model::prescribed; `tau` itself without any). One
  // evaluation of q̈, not counted in evaluations(); the last rhs's buffers are overwritten.
  Status driven_actuation(double t, const double* y, const VecX& tau, VecX& out);
  // ∂q̈/∂q and ∂q̈/∂v at τ held (the analytic derivatives at applied_actuation(), with (M^s)⁻¹)
  // made those of the driven motion, whose τ_P(q, v) holds q̈_P = q̈*_P:
  //   ∂τ_P/∂x = ((M⁻¹)_PP)⁻¹ (∂q̈*_P/∂x − E_Pᵀ ∂q̈/∂x),   ∂q̈/∂x += M⁻¹_{:,P} ∂τ_P/∂x,
  // with ∂q̈*_P/∂q_P = −ω², ∂q̈*_P/∂v_P = −2ω (kPrescribedRate). Nothing without prescribed ones.
  void drive_jacobian(const MatX& Minv, MatX& dqdd_dq, MatX& dqdd_dv) const;

  // The first non-finite entry of y as a failed Status ("q_name", "qd_name" or "W"), or ok.
  Status check_state(double t, const double* y) const;

  // Mechanical energy at y (kinetic, potential; the work W is y's last entry).
  Energy energy_at(const double* y);
  // τ at (t, q, v) as applied: the controller's when there is one, else τ(t) (zero when
  // passive), saturated at the joints' effort limits.
  void tau_at(double t, const VecX& q, const VecX& v, VecX& tau) const;
  // The exception the controller threw in the last failed rhs, rethrown (then cleared); nothing
  // if it threw none.
  void rethrow_control_error();
  // τ(t) (zero when passive), saturated at the joints' effort limits |τ_i| ≤ effort_i.
  void actuation(double t, VecX& tau) const;
  // τ(t) as asked, before saturation; whether some |τ_i(t)| asked exceeds its effort limit
  // (under a controller, which is not called again for it: whether the last evaluation's did).
  void requested_actuation(double t, VecX& tau) const;
  bool saturated_at(double t) const;
  // The evaluations (rhs) whose τ was saturated, and per coordinate how many times it was.
  long saturated_evaluations() const { return saturated_evaluations_; }
  const std::vector<long>& saturations() const { return saturations_; }
  // The workspace of the last evaluation (rhs or energy_at).
  const Workspace& workspace() const { return ws_; }

 private:
  const Model& model_;
  Actuation tau_;
  Control control_;
  std::exception_ptr control_error_;
  std::function<bool()> interrupt_;
  std::chrono::steady_clock::time_point next_interrupt_look_;
  bool interrupt_requested();
  Workspace ws_;
  std::unique_ptr<LoopWorkspace> loops_;  // with constraints only
  double baumgarte_ = kDefaultBaumgarte;
  bool flat_ = true;
  VecX q_c_;         // the chart centre (non-flat)
  VecX q_, qd_, u_;  // buffers: q, q̇ (v), τ at the evaluated state
  long evaluations_ = 0;
  long saturated_evaluations_ = 0;
  bool last_saturated_ = false;  // the last evaluation's τ was saturated
  std::vector<long> saturations_;
  void count_saturation(VecX& tau);
  // q̈ into ws_.qdd at (q_, qd_) under u_: the tree's, or the constrained one with loops.
  Status accelerations();
  // The torques that hold the prescribed coordinates on their motion (Model::prescribed), added
  // to u_ and their effect to ws_.qdd.
  Status drive_prescribed(double t);
  VecX free_qdd_;     // q̈ before the prescribed torques
  MatX driven_cols_;  // M⁻¹'s columns of the prescribed coordinates (n × k)
  MatX driven_gain_;  // their rows: (M⁻¹)_PP (k × k)
  VecX driven_need_;  // q̈*_P − q̈_P, then τ_P (k)
};

// The rate (1/s) at which the simulator pulls a prescribed coordinate back onto its motion after
// the integrator's drift or a start off it: q̈* = q̈(t) + 2ω (q̇(t) − q̇) + ω² (q(t) − q).
inline constexpr double kPrescribedRate = 10;

// Power of the non-conservative forces at the state of the last evaluate(model, ws, q, q̇, τ):
//   P_nc = q̇ᵀ τ + Σ_j P_j(θ_j, θ̇_j) + Σ_b τ_b · ω_b      (actuation, joints, body torques),
// P_j the joint's damper, Coulomb friction and stop dissipation (core/joints/passive.hpp).
// Gravity, constant point loads, springs and the stops' elastic part are conservative: they are
// in E's potential.
double nonconservative_power(const Model& model, const Workspace& ws, const VecX& qd,
                             const VecX& tau);

// "at t = 0.125 s: " with the time printed to the digits that matter.
std::string at_time(double t);

}  // namespace femdyn
