#include "validation/validate.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "core/body_inertia.hpp"
#include "core/compile_level.hpp"
#include "core/equations.hpp"
#include "core/errors.hpp"
#include "core/fixed_step.hpp"
#include "core/inertia.hpp"
#include "core/kinematics.hpp"
#include "core/model.hpp"
#include "core/sampling.hpp"
#include "validation/twin.hpp"
#include "validation/urdf_twin.hpp"

namespace femdyn::validation {

namespace {

// The θ of the joints on the tree path between bodies a and b.
std::vector<int> path_joints(const Model& m, int a, int b) {
  std::vector<int> up_a, up_b;
  for (int x = a; x >= 0; x = m.bodies[x].parent) up_a.push_back(x);
  for (int x = b; x >= 0; x = m.bodies[x].parent) up_b.push_back(x);
  while (!up_a.empty() && !up_b.empty() && up_a.back() == up_b.back())
    up_a.pop_back(), up_b.pop_back();  // the common ancestors
  std::vector<int> out;
  for (const auto* side : {&up_a, &up_b})
    for (int x : *side)
      if (m.bodies[x].joint.theta >= 0) out.push_back(m.bodies[x].joint.theta);
  return out;
}

// An element spanning two bodies as the twin's rod: it must be a uniform rod
// (m_e = (m/6)[[2·1, 1], [1, 2·1]] on its two ends' translations) and close the loop of exactly
// one coupled joint on the tree path between its ends.
TwinRod twin_rod(const Model& m, const ElementEntry& e, const TwinModel& t) {
  const auto nodes = e.element->nodes();
  if (nodes.size() != 2 || e.node_body[0] == e.node_body[1])
    throw ModelError(e.where,
                     "the Simbody twin builds an element spanning bodies only as a rod "
                     "between two bodies");
  const MatX me = e.element->local_mass();
  TwinRod r;
  r.mass = 3 * me(0, 0);
  MatX rod = MatX::Zero(12, 12);
  for (int i = 0; i < 3; ++i) {
    rod(i, i) = rod(6 + i, 6 + i) = r.mass / 3;
    rod(i, 6 + i) = rod(6 + i, i) = r.mass / 6;
  }
  if (me.rows() != 12 || max_abs(me - rod) > 1e-12 * std::max(max_abs(rod), 1e-300))
    throw ModelError(e.where,
                     "the Simbody twin builds an element spanning bodies only as a "
                     "uniform rod (m_e = (m/6)[[2, 1], [1, 2]] on its ends)");
  r.name = e.where;
  r.body_a = e.node_body[0], r.body_b = e.node_body[1];
  r.point_a = nodes[0].position, r.point_b = nodes[1].position;
  Workspace ws(m);  // its length, kept by every posture (compile checks it)
  propagate(m, ws, reference_posture(m), VecX::Zero(m.n()), {.jacobian = false, .bias = false});
  r.length = span_length(e, ws);
  std::string closes;  // the coupled joint(s) on its path, for the message
  for (int theta : path_joints(m, r.body_a, r.body_b))
    for (const TwinLaw& law : t.laws)
      if (law.theta == theta) {
        closes += (closes.empty() ? "'" : ", '") + law.name + "'";
        if (r.closes >= 0)
          throw ModelError(e.where, "the rod spans more than one coupled joint (" + closes +
                                        "): the Simbody twin cannot tell which loop it closes");
        r.closes = theta;
      }
  if (r.closes < 0)
    throw ModelError(e.where,
                     "the rod spans no coupled joint, so it closes no loop the Simbody "
                     "twin can build (its constraint would repeat the couplings)");
  for (const TwinRod& other : t.rods)
    if (other.closes == r.closes)
      throw ModelError(e.where, "two rods close the loop of the same joint");
  return r;
}

// A core law as the twin's callable (twin.hpp reads no C++20: no std::span in its interface).
std::function<bool(const double*, double&, double*, double*)> callable(
    std::shared_ptr<const CouplingFunction> law) {
  return [law = std::move(law)](const double* x, double& f, double* df, double* d2f) {
    const std::size_t k = law->arity();
    return law->evaluate({x, k}, f, {df, k}, {d2f, k * k});
  };
}

// The closed-loop form of the twin (twin.hpp): every coupled joint a law of the joints it
// follows, every element that spans bodies a rod.
void add_loops(const Model& m, TwinModel& t) {
  if (m.coupling_level) {
    t.coordinate_theta = m.coupling_level->coordinate_theta;
    for (const CoupledJoint& j : m.coupling_level->coupled)
      t.laws.push_back({j.theta, j.sources, callable(j.law), j.name});
  } else {  // linear couplings, each coordinate a joint of its own
    for (int k = 0; k < m.n(); ++k) {
      const int j = independent_theta(t, k);
      if (j < 0)
        throw ModelError(m.where, "coordinate '" + m.coordinate_names[k] +
                                      "' drives no joint directly: the closed-loop Simbody twin "
                                      "needs each coordinate to be a joint");
      t.coordinate_theta.push_back(j);
    }
    for (int j = 0; j < m.n_theta(); ++j) {
      if (std::find(t.coordinate_theta.begin(), t.coordinate_theta.end(), j) !=
          t.coordinate_theta.end())
        continue;
      TwinLaw law{j, {}, {}, m.bodies[m.theta_joint[j]].joint.name};
      std::vector<double> ratios;
      for (int k = 0; k < m.n(); ++k)
        if (t.C(j, k) != 0)
          law.sources.push_back(t.coordinate_theta[k]), ratios.push_back(t.C(j, k));
      law.law = callable(std::make_shared<LinearCoupling>(std::move(ratios), t.theta0[j]));
      t.laws.push_back(std::move(law));
    }
  }
  for (const ElementEntry& e : m.elements)
    if (e.spans) t.rods.push_back(twin_rod(m, e, t));
}

}  // namespace

// What the twin reads of the model; each body's mass properties are the sum of its elements'.
TwinModel twin_model(const Model& m) {
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
  const bool spans = std::any_of(m.elements.begin(), m.elements.end(),
                                 [](const ElementEntry& e) { return e.spans; });
  if (m.coupling_level || spans) add_loops(m, t);
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
  Workspace ws(m);
  for (double target : times) {
    const Status st = rk4.advance_to(target);
    if (st.non_finite) throw std::runtime_error("along the trajectory: " + st.message);
    if (!st.ok) return false;
    joint_state(m, ws, rk4.q(), rk4.qd());
    VecX x(2 * m.n_theta());
    x << ws.theta, ws.theta_dot;
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

  // Each body's elements must sum to a rigid body: nothing else can be built in Simbody.
  TwinModel tm;
  try {
    tm = twin_model(m);
  } catch (const ModelError& e) {
    r.failure = e.what();
    return r;
  }
  if (tm.closed_loop())
    r.notes.push_back("closed loop: " + std::to_string(tm.laws.size()) + " coupled joint(s), " +
                      std::to_string(tm.rods.size()) +
                      " rod(s); Simbody's equations from its constrained forward dynamics");
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
  if (tm.closed_loop()) r.quantities.push_back({"loop", 0, 0, o.tolerance});
  QuantityError &eM = r.quantities[0], &eh = r.quantities[1], &eQ = r.quantities[2],
                &eqdd = r.quantities[3], &etau = r.quantities[4];
  // The loop's closure at femdyn's θ = g(q), θ̇ = G q̇: Simbody's constraint errors relative to
  // the longest rod (m) and its speed, or in rad and rad/s for couplers alone.
  double length = 1;
  if (!tm.rods.empty()) {
    length = 0;
    for (const TwinRod& rod : tm.rods) length = std::max(length, rod.length);
  }

  std::mt19937 rng(o.seed);
  VecX q0, qd0;
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng);
    const VecX qd = random_uniform(m.n(), o.qd_scale, rng);
    const VecX tau = random_uniform(m.n(), o.tau_scale, rng);
    const VecX qdd = random_uniform(m.n(), o.qdd_scale, rng);
    if (k == 0) q0 = q, qd0 = qd;

    const TwinEquations s = twin.equations(q, qd, tau);
    if (tm.closed_loop()) {
      QuantityError& loop = r.quantities[5];
      const double speed = length * std::max(1.0, max_abs(qd));
      loop.max_abs = std::max({loop.max_abs, s.loop_position_error, s.loop_velocity_error});
      loop.max_rel =
          std::max({loop.max_rel, s.loop_position_error / length, s.loop_velocity_error / speed});
    }
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
