// Integrators of M^s q̈ + h = Q in time (docs/simulation.md). Each is an object that owns its
// buffers and its right-hand side (sim/motion.hpp), takes a plain options struct with defaults
// and a check that names the bad field, and after the first step allocates nothing per step.
//
//   Rk4             classical fixed-step Runge–Kutta, order 4, 4 evaluations a step
//   SymplecticEuler semi-implicit Euler, order 1, 1 evaluation a step:
//                     q̇ₖ₊₁ = q̇ₖ + dt q̈(tₖ, qₖ, q̇ₖ),  qₖ₊₁ = qₖ + dt q̇ₖ₊₁
//   DormandPrince   adaptive explicit 5(4) with error control and dense output (SUNDIALS ARKODE)
//   Bdf             adaptive implicit BDF 1–5 with a Newton solver for stiff models (SUNDIALS
//                   CVODE), Jacobian ∂f/∂y = [[0, I], [∂q̈/∂q, ∂q̈/∂q̇]] by finite differences
//
// The state is y = (q, q̇, W), W the work of the non-conservative forces. A failure (step-size
// underflow, NaN in the state, M^s losing definiteness, a Newton solver that does not converge)
// is a failed Status naming the time, the quantity and the likely cause; the integrator keeps
// its last good state. Divergence is looked for first (sim/divergence.hpp): a run whose state
// blows up fails as "the solution diverges" with the stiffest mode and the step it allows, even
// where the blown-up state then makes M^s singular or overflows.
#pragma once
#include <limits>
#include <memory>
#include <string>
#include <string_view>

#include "sim/divergence.hpp"
#include "sim/motion.hpp"

namespace femdyn {

enum class IntegratorKind { Rk4, Euler, Dopri, Bdf };
const char* integrator_name(IntegratorKind kind);    // "rk4", "euler", "dopri", "bdf"
const char* integrator_method(IntegratorKind kind);  // e.g. "Dormand–Prince 5(4), SUNDIALS ARKODE"
inline constexpr IntegratorKind kIntegrators[] = {IntegratorKind::Rk4, IntegratorKind::Euler,
                                                  IntegratorKind::Dopri, IntegratorKind::Bdf};
bool parse_integrator(std::string_view name, IntegratorKind& kind);
bool is_adaptive(IntegratorKind kind);

struct FixedStepOptions {
  double dt = 1e-3;             // s
  long max_steps = 10'000'000;  // a run that needs more steps is refused before it starts
  std::string check() const;    // "" if valid, else "dt: …" naming the field
};

struct AdaptiveOptions {
  double rtol = 1e-6;           // relative tolerance on each component of y
  double atol = 1e-8;           // absolute tolerance (rad, m, rad/s, m/s, J)
  double h_max = 0;             // largest step (s); 0: no limit
  long max_steps = 10'000'000;  // per advance_to
  // advance_to(t_out) interpolates (dense output: ARKODE's Hermite interpolant of degree 4 for
  // the explicit methods, CVODE's Nordsieck history for BDF), which costs no step but adds an
  // interpolation error ~10x the step's own on the examples measured (docs/simulation.md).
  // With stop_at_outputs the method lands on each t_out with a shortened step instead.
  bool stop_at_outputs = false;
  // BDF's Jacobian: analytic (core/derivatives/derivatives.hpp) where the derivatives cover the
  // model and τ does not depend on the state; false: forward differences of forward dynamics
  // always.
  bool analytic_jacobian = true;
  // BDF's largest order (1–5). BDF1 and BDF2 are A-stable; BDF3–5 are not: their regions leave
  // out a wedge about the imaginary axis (A(α)-stable, α = 86°, 73°, 52°), so an undamped fast
  // oscillation (a flexible bar's axial modes) holds them to steps near 1/ω, and 2 lets the
  // step follow the slow motion instead (docs/simulation.md).
  int max_order = 5;
  std::string check() const;
};

struct IntegratorStats {
  long steps = 0, rejected = 0;  // accepted steps; steps rejected by error or Newton failure
  long rhs_evals = 0;            // evaluations of forward dynamics (incl. Jacobian columns)
  long jac_evals = 0;            // Jacobian evaluations (BDF)
  double wall_time = 0;          // s, inside advance_to
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual IntegratorKind kind() const = 0;
  const char* name() const { return integrator_name(kind()); }

  // Starts a run at (t0, q0, q̇0) with W = 0; clears the statistics. A model with closed loops
  // starts from (q0, q̇0) moved onto its constraints (Motion::project; StateError when the loops
  // cannot close there). An adaptive method never
  // steps past t_stop (τ(t) may not be defined there); by default it may overshoot t_out and
  // interpolate back.
  void reset(double t0, const VecX& q0, const VecX& qd0,
             double t_stop = std::numeric_limits<double>::infinity());
  // Advances to t_out ≥ t(): fixed-step methods take steps of dt and shorten the last one to
  // land on t_out; adaptive ones stop at t_out by dense output. On failure the state stays at
  // the last good step (t() < t_out) and the Status says why.
  Status advance_to(double t_out);
  // τ jumps at t() (a controller's new sample, sim/control_loop.hpp): the method restarts from
  // the current state, W and the statistics kept, and never steps past t_stop. A fixed-step
  // method continues on its grid (no step of it straddles t(): it landed there); an adaptive
  // one is reinitialised at t() (ERKStepReInit / CVodeReInit, on the memory it has: no
  // allocation), its first step the last one it took, so that no step, error estimate or BDF
  // history spans the jump.
  void restart(double t_stop);
  // The controller τ = u(t, q, v) in f from now on (Motion::set_control).
  void set_control(Control u) { motion_.set_control(std::move(u)); }
  // The τ held over the first period after reset (a sampled controller's first output, or
  // ControlLoop::step(τ)'s): the start state's τ that a divergence's cause linearises at. Without
  // it, f's τ at the start is asked (τ(t0), or a controller inside f at (q0, q̇0)).
  void hold_start_tau(const VecX& tau) {
    tau0_ = tau;
    tau0_held_ = true;
  }
  // One step: dt for a fixed-step method, one internal (error-controlled) step for an adaptive
  // one; never past t_stop.
  Status step();
  // Whether a run to t_end can be made: a fixed-step run of more than max_steps steps, or with
  // a dt below the time's resolution (t + dt == t), is refused here, before any work, with the
  // step count, an estimate of its time and how to raise the limit.
  virtual Status plan(double t_end);
  // "dt = 0.001 s" or "rtol 1e-06, atol 1e-08": the setting a message quotes.
  virtual std::string setting() const = 0;

  double t() const { return t_; }
  VecX q() const {  // (y holds chart coordinates when a joint's q is not a vector space)
    VecX q;
    motion_.configuration(y_.data(), q);
    return q;
  }
  auto qd() const { return y_.segment(motion_.n(), motion_.n()); }
  double work() const { return y_[2 * motion_.n()]; }
  // (q, q̇, W) as reported (n_q + n + 1 entries): y itself unless y holds chart coordinates.
  VecX state() const {
    if (motion_.flat()) return y_;
    VecX s(y_.size() + motion_.model().n_q() - motion_.n());
    s << q(), y_.tail(motion_.n() + 1);
    return s;
  }
  const VecX& y() const { return y_; }
  const IntegratorStats& stats() const { return stats_; }
  Motion& motion() { return motion_; }
  const DivergenceWatch& divergence() const { return watch_; }
  // The state's energy counted as supplied (DivergenceWatch::accept): after a divergence verdict
  // that the caller's theory overrules, the run goes on from the state it reached.
  void accept_energy() { watch_.accept(motion_.energy_at(y_.data()), work()); }

 protected:
  Integrator(const Model& model, Actuation tau);
  virtual void start() = 0;         // after reset: (re)initialise the method at (t_, y_, t_stop_)
  virtual void restart_method() {}  // restart(): the method's own (fixed step: nothing)
  virtual Status advance(double t_out) = 0;  // the method's own advance_to
  virtual Status one_step() = 0;             // the method's own step
  // After an accepted step: the divergence test when the rates have grown (sim/divergence.hpp).
  Status watch();
  // A failure, unless the last good state shows the solution diverging: then that, first.
  Status explain(Status failure);
  // The failed Status "at t = …: the solution diverges …: <cause>".
  Status diverged();
  // The fixed step, or 0 for an adaptive method (for the divergence's cause).
  virtual double fixed_dt() const { return 0; }
  Motion motion_;
  VecX y_, y0_, q0_, tau0_;
  bool tau0_held_ = false;
  double t_ = 0, t0_ = 0, t_stop_ = 0;
  IntegratorStats stats_;
  DivergenceWatch watch_;
};

struct IntegratorOptions {  // what make_integrator reads: the one that applies to `kind`
  IntegratorKind kind = IntegratorKind::Dopri;
  FixedStepOptions fixed;
  AdaptiveOptions adaptive;
  std::string check() const;
};

// The memory a run of `kind` holds besides its output rows (core/workspace/memory.hpp): the
// workspace (evaluation_bytes where forward dynamics or the energy forms M^s), and bdf's dense (2n
// + 1) x (2n + 1) Jacobian and its factor. For the estimate made before make_integrator.
double integrator_bytes(const Model& model, IntegratorKind kind);

// The integrator of options.kind for the model under τ(t). Throws std::invalid_argument with
// options.check()'s message if the options are invalid.
std::unique_ptr<Integrator> make_integrator(const Model& model, const IntegratorOptions& options,
                                            Actuation tau = {});

}  // namespace femdyn
