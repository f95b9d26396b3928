#include "sim/integrator.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "core/model/errors.hpp"
#include "core/workspace/memory.hpp"
#include "sim/fixed_step.hpp"
#include "sim/stability.hpp"
#include "sim/sundials_integrators.hpp"

namespace femdyn {
namespace {

std::string bad(const char* field, const std::string& what, double value) {
  return std::string(field) + ": " + what + ", got " + format_number(value, "%g");
}

}  // namespace

const char* integrator_name(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::Rk4:
      return "rk4";
    case IntegratorKind::Euler:
      return "euler";
    case IntegratorKind::Dopri:
      return "dopri";
    case IntegratorKind::Bdf:
      return "bdf";
  }
  return "?";
}

const char* integrator_method(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::Rk4:
      return "classical Runge-Kutta 4, fixed step";
    case IntegratorKind::Euler:
      return "semi-implicit (symplectic) Euler, fixed step";
    case IntegratorKind::Dopri:
      return "Dormand-Prince 5(4), adaptive, SUNDIALS ARKODE";
    case IntegratorKind::Bdf:
      return "BDF 1-5 with Newton, adaptive, SUNDIALS CVODE";
  }
  return "?";
}

bool parse_integrator(std::string_view name, IntegratorKind& kind) {
  for (IntegratorKind k : kIntegrators)
    if (name == integrator_name(k)) {
      kind = k;
      return true;
    }
  return false;
}

bool is_adaptive(IntegratorKind kind) {
  return kind == IntegratorKind::Dopri || kind == IntegratorKind::Bdf;
}

std::string FixedStepOptions::check() const {
  if (!(dt > 0) || !std::isfinite(dt)) return bad("dt", "the step must be a positive number", dt);
  if (max_steps < 1) return bad("max_steps", "must be at least 1", static_cast<double>(max_steps));
  return {};
}

std::string AdaptiveOptions::check() const {
  if (!(rtol > 0 && rtol < 1)) return bad("rtol", "the relative tolerance must be in (0, 1)", rtol);
  if (rtol < 1e-15) return bad("rtol", "below double round-off (1e-15)", rtol);
  if (!(atol > 0) || !std::isfinite(atol))
    return bad("atol", "the absolute tolerance must be a positive number", atol);
  if (!(h_max >= 0) || !std::isfinite(h_max))
    return bad("h_max", "must be >= 0 (0: no limit)", h_max);
  if (max_steps < 1) return bad("max_steps", "must be at least 1", static_cast<double>(max_steps));
  if (max_order < 1 || max_order > 5)
    return bad("max_order", "BDF's order is 1 to 5", static_cast<double>(max_order));
  return {};
}

std::string IntegratorOptions::check() const {
  return is_adaptive(kind) ? adaptive.check() : fixed.check();
}

Integrator::Integrator(const Model& model, Actuation tau)
    : motion_(model, std::move(tau)), y_(VecX::Zero(2 * model.n() + 1)) {}

void Integrator::reset(double t0, const VecX& q0, const VecX& qd0, double t_stop) {
  const int n = motion_.n();
  const int nq = motion_.model().n_q();
  if (q0.size() != nq || qd0.size() != n)
    throw std::invalid_argument("Integrator::reset: expected q0 of size " + std::to_string(nq) +
                                " and qd0 of size " + std::to_string(n));
  motion_.start_chart(q0, y_.data());
  y_.segment(n, n) = qd0;
  y_[2 * n] = 0.0;
  // Closed loops start on their constraints (assembled, the velocity projected).
  if (Status p = motion_.project(t0, y_.data()); !p.ok) throw StateError(p.message);
  y0_ = y_;
  q0_ = q0;
  tau0_held_ = false;
  t_ = t0_ = t0;
  t_stop_ = t_stop;
  stats_ = {};
  const Energy E0 = motion_.energy_at(y_.data());
  watch_.start(E0, potential_reach(motion_.model(), motion_.workspace()),
               qd0.size() ? qd0.cwiseAbs().maxCoeff() : 0.0);
  start();
}

void Integrator::restart(double t_stop) {
  t_stop_ = t_stop;
  restart_method();
}

Status Integrator::advance_to(double t_out) {
  const auto begin = std::chrono::steady_clock::now();
  Status st = t_out > t_ ? advance(t_out) : Status{};
  st = st.ok ? watch() : st.interrupted ? st : explain(std::move(st));
  stats_.wall_time +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return st;
}

Status Integrator::step() {
  if (t_ >= t_stop_) return {};
  const auto begin = std::chrono::steady_clock::now();
  Status st = one_step();
  st = st.ok ? watch() : st.interrupted ? st : explain(std::move(st));
  stats_.wall_time +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return st;
}

Status Integrator::plan(double) { return {}; }

double integrator_bytes(const Model& m, IntegratorKind kind) {
  const double n = m.n();
  const bool forms_mass = m.dynamics_route == DynamicsRoute::Cholesky ||
                          m.mass_route == MassRoute::Transform || m.coupling_level;
  // Without M^s (the articulated and composite routes): buffers of n and per body only.
  double bytes = forms_mass ? evaluation_bytes(m) : 2e3 * static_cast<double>(m.bodies.size());
  if (kind == IntegratorKind::Bdf) bytes += 2 * dense_bytes(2 * n + 1, 2 * n + 1);
  return bytes;
}

Status Integrator::watch() {
  const int n = motion_.n();
  const double qd_norm = n ? qd().cwiseAbs().maxCoeff() : 0.0;
  if (!watch_.due(qd_norm)) return {};
  if (watch_.look(motion_.energy_at(y_.data()), work(), qd_norm) && watch_.confirmed())
    return diverged();
  return {};
}

Status Integrator::explain(Status failure) {
  if (failure.diverged) return failure;
  const int n = motion_.n();
  const double qd_norm = n ? qd().cwiseAbs().maxCoeff() : 0.0;
  if (watch_.look(motion_.energy_at(y_.data()), work(), qd_norm)) return diverged();
  return failure;
}

Status Integrator::diverged() {
  const int n = motion_.n();
  VecX tau0 = VecX::Zero(n);
  try {  // (τ at the start, for the cause: the first period's, or f's at (t0, q0, q̇0))
    if (tau0_held_)
      tau0 = tau0_;
    else
      motion_.tau_at(t0_, q0_, y0_.segment(n, n), tau0);
  } catch (...) {
    tau0.setZero(n);
  }
  if (tau0.size() != n) tau0.setZero(n);
  // (an energy that overflowed is said so, never printed as NaN)
  const double gain = watch_.gain();
  const std::string held =
      std::isfinite(gain) ? "the state holds " + format_short(gain) + " J more energy than the "
                          : "the state's energy overflowed (NaN or Inf), "
                            "from the ";
  Status st{false,
            at_time(t_) + "the solution diverges (" + held + format_short(watch_.supplied()) +
                " J it started with and was given): " +
                divergence_cause(motion_.model(), kind(), fixed_dt(), setting(), q0_,
                                 y0_.segment(n, n), tau0, motion_.baumgarte()),
            -1};
  st.diverged = true;
  return st;
}

std::unique_ptr<Integrator> make_integrator(const Model& model, const IntegratorOptions& o,
                                            Actuation tau) {
  if (const std::string why = o.check(); !why.empty()) throw std::invalid_argument(why);
  switch (o.kind) {
    case IntegratorKind::Rk4:
      return std::make_unique<Rk4>(model, o.fixed, std::move(tau));
    case IntegratorKind::Euler:
      return std::make_unique<SymplecticEuler>(model, o.fixed, std::move(tau));
    case IntegratorKind::Dopri:
      return std::make_unique<DormandPrince>(model, o.adaptive, std::move(tau));
    case IntegratorKind::Bdf:
      return std::make_unique<Bdf>(model, o.adaptive, std::move(tau));
  }
  return nullptr;
}

}  // namespace femdyn
