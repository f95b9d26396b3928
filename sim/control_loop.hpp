// A controller in the loop: τ = u(t, q, v) (sim/motion.hpp's Control) driving an integrator of
// sim/integrator.hpp, in one of two modes the user chooses (docs/control.md):
//
//   PerEvaluation   u is part of the right-hand side: every evaluation of
//                     f(t, y) = (q̇, (M^s)⁻¹ (Q(q, q̇, u(t, q, q̇)) − h), P_nc)
//                   calls it (4 a step for rk4, 7 for dopri, 1 + 2n per Jacobian for bdf).
//                   The closed loop is one ODE: the integrator's order and, for dopri and bdf,
//                   its error control cover the plant and the controller together. A
//                   controller that is discontinuous in t or in the state (a switching law, a
//                   saturation's kink, a table lookup) breaks the smoothness the method's order
//                   assumes: an adaptive method pays in rejected steps around each jump, a fixed
//                   step in accuracy. step() advances one period T (only a reporting grid).
//
//   ZeroOrderHold   a sampled controller, as a digital one runs: at t_k = t0 + k T,
//                     τ_k = u(t_k, q(t_k), v(t_k)),   τ(t) = τ_k  for t in [t_k, t_{k+1}),
//                   each hold interval integrated as a smooth problem of its own. τ jumps at
//                   every t_k, so the method is restarted there (Integrator::restart: a fixed
//                   step lands on t_k and continues on its grid; an adaptive one stops exactly
//                   at t_{k+1}, never steps past it, and is reinitialised). The error control
//                   covers the plant only: the sampling is the controller's own discretisation
//                   (the held τ differs from u along the motion by O(T)), which no tolerance
//                   reduces. Over a fixed horizon the ZOH motion tends to the per-evaluation
//                   one at order 1 in T (tests/test_control.cpp).
//
// In both modes W (the last entry of y) integrates P_nc = q̇ᵀ τ − Σ c θ̇² + … with the τ actually
// applied, so E(t) − E(0) = W(t) holds under the controller as under a prescribed τ(t).
// Buffers are sized at construction and reset, and an adaptive method's restart reinitialises
// SUNDIALS' memory in place: a period allocates nothing but what the controller does (tested
// for rk4, dopri and bdf in both modes).
#pragma once
#include <memory>
#include <string>

#include "sim/integrator.hpp"

namespace femdyn {

enum class ControlMode { PerEvaluation, ZeroOrderHold };

struct ControlLoopOptions {
  ControlMode mode = ControlMode::ZeroOrderHold;
  double period = 1e-3;       // T (s): the sampling period (ZOH), or the length of one step()
  std::string check() const;  // "" if valid, else "period: …"
};

class ControlLoop {
 public:
  // An integrator of `integrator` on the model, driven by u (none: step(tau) only). Throws
  // std::invalid_argument naming a bad option.
  ControlLoop(const Model& model, const IntegratorOptions& integrator,
              const ControlLoopOptions& options, Control u = {});
  ControlLoop(const ControlLoop&) = delete;  // (the integrator's f refers to this loop)
  ControlLoop& operator=(const ControlLoop&) = delete;

  // Starts at (t0, q0, v0) with W = 0; the first sample is at t0.
  void reset(double t0, const VecX& q0, const VecX& v0);
  // One control period [t_k, t_{k+1}]: ZOH samples u at t_k and holds it (without a
  // controller: the last τ held, zero after reset); per evaluation, u is called inside f. On
  // failure the state stays at the integrator's last good step; an exception the controller threw
  // is rethrown.
  Status step();
  // One period with τ given and held (ZOH whatever the mode; the controller is not called). A τ
  // of the wrong size or not finite is a failed Status naming it.
  Status step(const VecX& tau);
  // Periods until t reaches t_end (whole periods: stops at the first t_k ≥ t_end). A fixed-step
  // run beyond max_steps is refused first (Integrator::plan). A failure (a divergence, the
  // controller's τ out of range) names the controller as its cause where the closed loop at the
  // run's start implicates it (sim/controller_diagnosis.hpp).
  Status run(double t_end);
  // That clause for a run that started at (t, q, v) under the controller u, held over each
  // period (`held`) or called inside f: "" when the loop there does not implicate it.
  std::string controller_clause(const Control& u, double t, const VecX& q, const VecX& v,
                                bool held) const;

  // The controller from now on (empty: none).
  void set_controller(Control u) { u_ = std::move(u); }

  Integrator& integrator() { return *integ_; }
  const Integrator& integrator() const { return *integ_; }
  const ControlLoopOptions& options() const { return options_; }
  double t() const { return integ_->t(); }
  long period_index() const { return k_; }  // k: the periods advanced since reset
  double sample_time(long k) const { return t0_ + static_cast<double>(k) * options_.period; }
  const VecX& held() const { return held_; }        // the τ held over the last ZOH period
  long controller_calls() const { return calls_; }  // ZOH samples taken by step()

 private:
  // Integrates [t_k, t_{k+1}]: with held_ unless per_evaluation_.
  Status advance_period();
  bool stable_in_f();  // theory's word on the energy watch's verdict (control_loop.cpp)
  const Model& model_;
  ControlLoopOptions options_;
  Control u_;
  std::unique_ptr<Integrator> integ_;
  VecX held_, q_, v_;  // τ_k, and q_k, v_k for the sample
  double t0_ = 0;
  double fixed_dt_ = 0;  // the integrator's fixed step (0: adaptive)
  long k_ = 0, calls_ = 0;
  bool per_evaluation_ = false;  // u inside f during this period
  bool was_held_ = true;         // the last period held τ (a switch of mode is a jump in τ)
};

// "tau has 3 entries, expected 4", "tau is NaN or Inf (mcp)", "tau of 'mcp' 1e+200 is out of
// range (…)" (beyond kMaxMagnitude, as --tau) or unactuated_problem's; "" when τ is usable.
std::string tau_problem(const Model& model, const VecX& tau);

// A τ that acts on a coordinate no actuator drives (Model::actuated: a free base, a joint with
// "actuated": false), named with its joint: "tau of 'base.x' is 2 (in magnitude), but no
// actuator drives it (…)"; "" when τ is zero off the actuated coordinates. `tau`: n entries, τ
// or, for a table, its largest |τ_i| over the rows (ActuationTable::largest). Every door that runs
// the mechanism under a τ asks it: simulate, femdyn.simulate, the Simulator's step and
// controller, ControlLoop. Allocates nothing unless it refuses (a control period's check).
std::string unactuated_problem(const Model& model, const VecX& tau);

}  // namespace femdyn
