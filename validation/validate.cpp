#include "validation/validate.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "core/body_inertia.hpp"
#include "core/equations.hpp"
#include "core/errors.hpp"
#include "core/fixed_step.hpp"
#include "core/inertia.hpp"
#include "core/model.hpp"
#include "core/sampling.hpp"
#include "validation/twin.hpp"
#include "validation/urdf_twin.hpp"

namespace femdyn::validation {

// What a model with a nonlinear coupling law gets (issue 13: the closed-loop twin is next).
constexpr const char* kNoTwinForLaws =
    "has a nonlinear coupling law: its Simbody twin (a closed loop, or a coordinate coupler with "
    "a function) is not built yet, so only linear couplings are validated";

constexpr const char* kNoTwinForSpans =
    "an element spans two bodies: its Simbody twin (a closed loop) is not built yet";

// What the twin reads of the model; each body's mass properties are the sum of its elements'.
TwinModel twin_model(const Model& m) {
  if (m.coupling_level) throw ModelError(m.where, kNoTwinForLaws);
  for (const ElementEntry& e : m.elements)
    if (e.spans) throw ModelError(e.where, kNoTwinForSpans);
  TwinModel t;
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const Joint& j = m.bodies[b].joint;
    TwinBody tb;
    tb.name = m.bodies[b].name;
    tb.parent = m.bodies[b].parent;
    tb.joint = j.type == JointType::Revolute    ? TwinBody::Joint::Revolute
               : j.type == JointType::Prismatic ? TwinBody::Joint::Prismatic
                                                : TwinBody::Joint::Fixed;
    tb.R_pj = j.R_pj;
    tb.p_pj = j.p_pj;
    tb.axis = j.axis;
    tb.theta = j.theta;
    tb.stiffness = j.stiffness;
    tb.rest = j.rest;
    tb.damping = j.damping;
    const MassProperties p = body_mass_properties(m, static_cast<int>(b));
    tb.mass = p.mass;
    tb.com = p.com;
    tb.inertia_origin = p.inertia_origin;
    t.bodies.push_back(tb);
  }
  t.theta_body = m.theta_joint;
  t.C = MatX(m.C);
  t.theta0 = m.theta0;
  t.gravity = m.gravity;
  for (const PointLoad& l : m.point_loads)
    t.loads.push_back({l.body, l.point, l.force, Vec3::Zero()});
  for (const BodyTorque& q : m.torques)
    t.loads.push_back({q.body, Vec3::Zero(), Vec3::Zero(), q.torque});
  return t;
}

namespace {

void accumulate(QuantityError& e, const MatX& femdyn, const MatX& simbody) {
  const double d = max_abs(femdyn - simbody);
  const double scale = max_abs(simbody);
  e.max_abs = std::max(e.max_abs, d);
  e.max_rel = std::max(e.max_rel, scale > 0 ? d / scale : d);
}

// femdyn's passive motion by RK4 (core/fixed_step.hpp) at step dt, sampled at `times`
// (multiples of dt). Returns false if the integration failed (M^s singular on the way).
// An overflow along the trajectory (NaN or Inf) is an error, never a skipped comparison.
bool integrate(const Model& m, const VecX& q0, const VecX& qd0, const std::vector<double>& times,
               double dt, std::vector<VecX>& state, std::vector<double>& energy) {
  Rk4 rk4(m, {.dt = dt});
  rk4.reset(0, q0, qd0);
  for (double target : times) {
    const Status st = rk4.advance_to(target);
    if (st.non_finite) throw std::runtime_error("along the trajectory: " + st.message);
    if (!st.ok) return false;
    VecX x(2 * m.n_theta());
    x << m.C * rk4.q() + m.theta0, m.C * rk4.qd();
    state.push_back(std::move(x));
    energy.push_back(rk4.motion().energy_at(rk4.y().data()).total());
  }
  return true;
}

TrajectoryReport compare_trajectory(const Model& m, SimbodyTwin& twin, const VecX& q0,
                                    const VecX& qd0, const ValidationOptions& o) {
  TrajectoryReport r;
  r.t_end = o.t_end;
  if (o.t_end <= 0) {
    r.skipped = "--t-end 0";
    return r;
  }
  if (!twin.can_simulate(&r.skipped)) return r;
  const int samples = std::max(1, o.samples);
  // Halve femdyn's RK4 step until its own error estimate (dt against dt/2) is below the target,
  // within a budget of steps; sample times lie on the grid.
  std::vector<double> times;
  std::vector<VecX> x, x_half;
  std::vector<double> e, e_half;
  double dt = o.t_end / std::max(1.0, std::round(o.t_end / o.rk4_step));
  for (int i = 0; i <= samples; ++i) times.push_back(dt * std::round(o.t_end * i / samples / dt));
  const char* singular = "femdyn's mass matrix turned singular along the trajectory";
  if (!integrate(m, q0, qd0, times, dt, x, e)) {
    r.skipped = singular;
    return r;
  }
  for (;; dt /= 2) {
    x_half.clear(), e_half.clear();
    if (!integrate(m, q0, qd0, times, dt / 2, x_half, e_half)) {
      r.skipped = singular;
      return r;
    }
    double estimate = 0, scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      estimate = std::max(estimate, max_abs(x[i] - x_half[i]) / 15);
      scale = std::max(scale, max_abs(x_half[i]));
    }
    r.rk4_step = dt / 2;
    if (estimate <= o.rk4_target * scale || o.t_end / dt * 2 > o.max_rk4_steps) break;
    x.swap(x_half), e.swap(e_half);
  }
  // Simbody at its accuracy and 100x tighter: the difference estimates its own error.
  const std::vector<TwinSample> sim = twin.simulate(q0, qd0, times, o.simbody_accuracy);
  const std::vector<TwinSample> tight = twin.simulate(q0, qd0, times, o.simbody_accuracy / 100);
  r.run = true;
  r.rk4_error_estimate = 0;
  double scale = 1;
  for (std::size_t i = 0; i < times.size(); ++i) {
    VecX xs(x[i].size()), xt(x[i].size());
    xs << sim[i].theta, sim[i].theta_dot;
    xt << tight[i].theta, tight[i].theta_dot;
    const double err = max_abs(x_half[i] - xt);  // the finer runs of both
    r.t.push_back(times[i]);
    r.error.push_back(err);
    r.energy_femdyn.push_back(e_half[i]);
    r.energy_simbody.push_back(tight[i].energy);
    r.max_state_error = std::max(r.max_state_error, err);
    // RK4 is 4th order: x_dt − x_exact ≈ 16/15 (x_dt − x_dt/2); the finer run is 16x better.
    r.rk4_error_estimate = std::max(r.rk4_error_estimate, max_abs(x[i] - x_half[i]) / 15);
    r.simbody_error_estimate = std::max(r.simbody_error_estimate, max_abs(xs - xt));
    r.energy_change_femdyn = std::max(r.energy_change_femdyn, std::abs(e_half[i] - e_half[0]));
    r.energy_change_simbody =
        std::max(r.energy_change_simbody, std::abs(tight[i].energy - tight[0].energy));
    scale = std::max(scale, max_abs(xt));
  }
  // The two runs may differ by what each integrator gets wrong (with a margin of 10), plus
  // round-off. A comparison whose integrators are not that accurate proves nothing: the motion
  // is unresolved (chaotic over this time, or too fast) and fails with that reason.
  r.tolerance = 10 * (r.rk4_error_estimate + r.simbody_error_estimate) + 1e-12 * scale;
  r.resolved = r.tolerance <= o.resolved_tolerance * scale;
  return r;
}

}  // namespace

bool ValidationReport::pass() const {
  if (!failure.empty()) return false;
  for (const QuantityError& q : quantities)
    if (!q.pass()) return false;
  return trajectory.pass();
}

ValidationReport validate(const Model& m, const ValidationOptions& o) {
  ValidationReport r;
  r.model = m.name;
  r.n = m.n();
  r.states = o.states;
  if (m.explicit_table)
    r.notes.push_back(
        "the model gives its correlation table explicitly; DOFs it leaves out or "
        "joins are approximations of the rigid bodies Simbody simulates");
  for (const std::string& a : m.approximations) r.notes.push_back("approximation: " + a);
  if (m.coupling_level) {
    r.failure = kNoTwinForLaws;
    return r;
  }
  for (const ElementEntry& e : m.elements)
    if (e.spans) {
      r.failure = kNoTwinForSpans;
      return r;
    }

  // Each body's elements must sum to a rigid body: nothing else can be built in Simbody.
  const TwinModel tm = twin_model(m);
  for (std::size_t b = 0; b < tm.bodies.size(); ++b) {
    const TwinBody& tb = tm.bodies[b];
    const Mat3 I_com = tb.inertia_origin - point_inertia(tb.mass, tb.com);  // parallel axis
    if (tb.mass == 0 && !tb.inertia_origin.isZero(0)) {
      r.failure += (r.failure.empty() ? "" : "; ") + ("body '" + m.bodies[b].name +
                                                      "' has a rotary inertia but no mass, which a "
                                                      "Simbody body cannot have");
      continue;
    }
    if (const auto problem = inertia_problem(I_com, tb.inertia_origin.cwiseAbs().maxCoeff()))
      r.failure +=
          (r.failure.empty() ? "" : "; ") +
          ("body '" + m.bodies[b].name + "': its elements sum to no rigid body (" + *problem + ")");
  }
  if (!r.failure.empty()) return r;
  std::unique_ptr<SimbodyTwin> twin_ptr;
  try {
    twin_ptr = std::make_unique<SimbodyTwin>(tm);
  } catch (const std::exception& e) {
    r.failure = std::string("Simbody refused the twin: ") + e.what();
    return r;
  }
  SimbodyTwin& twin = *twin_ptr;
  Workspace ws(m);
  for (const char* name : {"M", "h", "Q", "qdd", "tau"})
    r.quantities.push_back({name, 0, 0, o.tolerance});
  QuantityError &eM = r.quantities[0], &eh = r.quantities[1], &eQ = r.quantities[2],
                &eqdd = r.quantities[3], &etau = r.quantities[4];

  std::mt19937 rng(o.seed);
  VecX q0, qd0;
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng);
    const VecX qd = random_uniform(m.n(), o.qd_scale, rng);
    const VecX tau = random_uniform(m.n(), o.tau_scale, rng);
    const VecX qdd = random_uniform(m.n(), o.qdd_scale, rng);
    if (k == 0) q0 = q, qd0 = qd;

    const TwinEquations s = twin.equations(q, qd, tau);
    const Status st = forward_dynamics(m, ws, q, qd, tau);
    evaluate(m, ws, q, qd, tau);
    accumulate(eM, ws.Ms, s.M);
    accumulate(eh, ws.h, s.h);
    accumulate(eQ, ws.Q, s.Q);
    if (st.ok) {
      accumulate(eqdd, ws.qdd, s.qdd);
    } else {
      eqdd.max_abs = eqdd.max_rel = INFINITY;
      r.notes.push_back("femdyn: " + st.message);
    }
    inverse_dynamics(m, ws, q, qd, qdd);
    accumulate(etau, ws.tau, twin.inverse_dynamics(q, qd, qdd));
  }
  if (o.states > 0) r.trajectory = compare_trajectory(m, twin, q0, qd0, o);
  return r;
}

QuantityError validate_urdf_import(const Model& m, const std::string& path,
                                   const ValidationOptions& o, std::string& failure) {
  QuantityError e{"import", 0, 0, o.tolerance};
  std::unique_ptr<UrdfTwin> twin;
  try {
    twin = std::make_unique<UrdfTwin>(path, m.gravity);
  } catch (const std::exception& ex) {
    failure = std::string("the independent URDF twin could not be built: ") + ex.what();
    return e;
  }
  Workspace ws(m);
  std::mt19937 rng(o.seed);
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng);
    const VecX qd = random_uniform(m.n(), o.qd_scale, rng);
    evaluate(m, ws, q, qd, VecX());
    const UrdfTwinEquations s = twin->equations(m.coordinate_names, q, qd);
    accumulate(e, ws.Ms, s.M);
    accumulate(e, ws.h, s.h);
    accumulate(e, ws.Q, s.Q);
  }
  return e;
}

}  // namespace femdyn::validation
