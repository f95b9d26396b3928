// The Simbody twin's description of a femdyn Model (validation/twin.hpp, TwinModel): its bodies
// and mobilizers, each body's mass properties summed from its elements, and a coupled or spanning
// mechanism's closed-loop form.
#include <algorithm>
#include <functional>

#include "compile/compile_level.hpp"
#include "core/dynamics/body_inertia.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/model/model.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"
#include "validation/validate_loops.hpp"

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
      if (moves(m.bodies[x].joint)) out.push_back(m.bodies[x].joint.idx_q);
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
    const std::vector<int> independent = independent_thetas(t);
    for (int k = 0; k < m.n(); ++k) {
      const int j = independent[k];
      if (j < 0)
        throw ModelError(m.where, "coordinate '" + m.coordinate_names[k] +
                                      "' drives no joint directly: the closed-loop Simbody twin "
                                      "needs each coordinate to be a joint");
      t.coordinate_theta.push_back(j);
    }
    std::vector<bool> is_coordinate(m.n_theta(), false);
    for (int j : t.coordinate_theta) is_coordinate[j] = true;
    const SpRowMat rows(t.C);
    for (int j = 0; j < m.n_theta(); ++j) {
      if (is_coordinate[j]) continue;
      TwinLaw law{j, {}, {}, m.bodies[m.theta_joint[j]].joint.name};
      std::vector<double> ratios;
      for (SpRowMat::InnerIterator it(rows, j); it; ++it)  // columns in increasing order
        if (it.value() != 0)
          law.sources.push_back(t.coordinate_theta[it.col()]), ratios.push_back(it.value());
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
    tb.joint = j.type;
    tb.R_pj = j.R_pj;
    tb.p_pj = j.p_pj;
    tb.axis = j.axis;
    tb.axis2 = j.axis2;
    for (const JointScalar& s : joint_parameters(j.type).scalars)
      tb.scalars[std::string(s.key)] = j.*(s.value);
    tb.theta = j.idx_q;
    tb.rate = j.idx_v;
    tb.stiffness = j.stiffness;
    tb.rest = j.rest;
    tb.damping = j.damping;
    tb.stop = j.stop;
    tb.lower = j.lower;
    tb.upper = j.upper;
    tb.stop_stiffness = j.stop_stiffness;
    tb.stop_dissipation = j.stop_dissipation;
    tb.friction = j.friction;
    tb.friction_velocity = j.friction_velocity;
    if (j.armature != 0)
      throw ModelError(j.where + "/armature",
                       "Simbody has no rotor inertia on a mobility (a rotor body would add the "
                       "gyroscopic terms femdyn's armature leaves out): the twin cannot check "
                       "this model; armature is checked against MuJoCo and closed forms");
    const MassProperties p = body_mass_properties(m, static_cast<int>(b));
    tb.mass = p.mass;
    tb.com = p.com;
    tb.inertia_origin = p.inertia_origin;
    t.bodies.push_back(tb);
  }
  t.theta_body = m.theta_joint;
  t.n_theta_q = m.n_theta_q;
  for (int k = 0; k < m.rate_damping.outerSize(); ++k)  // (identity coupling: q̇ = θ̇)
    for (SpMat::InnerIterator it(m.rate_damping, k); it; ++it)
      t.rate_damping.push_back(
          {static_cast<int>(it.row()), static_cast<int>(it.col()), it.value()});
  t.C = m.C;
  t.theta0 = m.theta0;
  t.gravity = m.gravity;
  for (const PointLoad& l : m.point_loads)
    t.loads.push_back({l.body, l.point, l.force, Vec3::Zero()});
  for (const BodyTorque& q : m.torques)
    t.loads.push_back({q.body, Vec3::Zero(), Vec3::Zero(), q.torque});
  const bool spans = std::any_of(m.elements.begin(), m.elements.end(),
                                 [](const ElementEntry& e) { return e.spans; });
  if (m.coupling_level || spans) add_loops(m, t);
  add_constraints_and_springs(m, t);
  return t;
}

}  // namespace femdyn::validation
