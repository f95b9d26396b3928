#include "compile/actuators.hpp"

#include <cmath>
#include <vector>

#include "core/joints/kernel.hpp"
#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"

namespace femdyn {
namespace {

void check_finite(double x, const std::string& where, const char* what) {
  if (std::isnan(x)) throw ModelError(where, std::string(what) + " is NaN");
  if (std::isfinite(x)) check_magnitude(x, where, what);
}

// What only a joint of one coordinate takes (armature aside: a spherical joint takes one too).
bool has_actuator(const JointSpec& js) {
  return js.gear != 1 || js.friction != 0 || std::isfinite(js.effort_limit) ||
         std::isfinite(js.velocity_limit) || js.stop;
}

// Each value finite and within the magnitudes femdyn takes (core/model/limits.hpp).
void check_magnitudes(const JointSpec& js) {
  const std::string& w = js.where;
  check_finite(js.armature, w + "/armature", "armature");
  check_finite(js.gear, w + "/gear", "gear ratio");
  check_finite(js.friction, w + "/friction", "friction");
  check_finite(js.friction_velocity, w + "/friction_velocity", "friction_velocity");
  check_finite(js.effort_limit, w + "/effort_limit", "effort_limit");
  check_finite(js.velocity_limit, w + "/velocity_limit", "velocity_limit");
  check_finite(js.stop_stiffness, w + "/stop/stiffness", "stop stiffness");
  check_finite(js.stop_dissipation, w + "/stop/dissipation", "stop dissipation");
}

// Which joint types take an actuator and an armature.
void check_joint_takes_them(const JointSpec& js, const Joint& j) {
  const std::string& w = js.where;
  if (has_actuator(js) && j.nv != 1)
    throw ModelError(w, std::string("a ") + std::string(joint_type_name(j.type)) +
                            " joint takes no gear, friction, effort or velocity limit or "
                            "stop (only joints of one coordinate do)");
  // A spherical or free joint's armature is I_a on each of its rates, as MuJoCo's dof_armature
  // (core/joints/rotor.hpp: a free joint's adds h_a = I_a ω × v on its linear rates).
  if (js.armature != 0 && j.nv != 1 && j.type != JointType::Spherical && j.type != JointType::Free)
    throw ModelError(w + "/armature", std::string("a ") + std::string(joint_type_name(j.type)) +
                                          " joint takes no armature (joints of one coordinate, "
                                          "spherical and free joints do)");
}

void check_ranges(const JointSpec& js) {
  const std::string& w = js.where;
  if (!(js.armature >= 0) || !std::isfinite(js.armature))
    throw ModelError(w + "/armature",
                     "must be finite and not negative, got " + format_number(js.armature));
  if (!(js.gear != 0) || !std::isfinite(js.gear))
    throw ModelError(w + "/gear", "must be finite and not zero, got " + format_number(js.gear));
  if (!(js.friction >= 0) || !std::isfinite(js.friction))
    throw ModelError(w + "/friction",
                     "must be finite and not negative, got " + format_number(js.friction));
  if (!(js.friction_velocity > 0) || !std::isfinite(js.friction_velocity))
    throw ModelError(w + "/friction_velocity",
                     "must be finite and positive, got " + format_number(js.friction_velocity));
  if (!(js.effort_limit > 0))
    throw ModelError(w + "/effort_limit",
                     "must be positive, got " + format_number(js.effort_limit));
  if (!(js.velocity_limit > 0))
    throw ModelError(w + "/velocity_limit",
                     "must be positive, got " + format_number(js.velocity_limit));
}

void check_stop(const JointSpec& js) {
  if (!js.stop) return;
  const std::string& w = js.where;
  if (!std::isfinite(js.lower) && !std::isfinite(js.upper))
    throw ModelError(w + "/stop", "a stop needs finite limits [lower, upper]");
  if (!(js.lower <= js.upper))
    throw ModelError(w + "/limits", "lower > upper: the stop would push both ways");
  if (!(js.stop_stiffness > 0) || !std::isfinite(js.stop_stiffness))
    throw ModelError(w + "/stop/stiffness",
                     "must be finite and positive, got " + format_number(js.stop_stiffness));
  if (!(js.stop_dissipation >= 0) || !std::isfinite(js.stop_dissipation))
    throw ModelError(w + "/stop/dissipation",
                     "must be finite and not negative, got " + format_number(js.stop_dissipation));
}

}  // namespace

void compile_actuator(const JointSpec& js, Joint& j) {
  check_magnitudes(js);
  check_joint_takes_them(js, j);
  check_ranges(js);
  check_stop(js);
  j.armature = js.armature;
  j.gear = js.gear;
  j.reflected_inertia = js.armature * js.gear * js.gear;  // I_a G²
  j.friction = js.friction;
  j.friction_velocity = js.friction_velocity;
  j.effort_limit = js.effort_limit;
  j.velocity_limit = js.velocity_limit;
  j.stop = js.stop;
  j.stop_stiffness = js.stop_stiffness;
  j.stop_dissipation = js.stop_dissipation;
  j.actuated = js.actuated.value_or(j.type != JointType::Free);
}

namespace {

// M_a = Cᵀ diag(a) C, a_j = I_a G² of θ̇_j's joint: Σ_j a_j C_jᵀ C_j over the rows of C.
void compile_armature_mass(Model& m) {
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < m.n_theta(); ++j) {
    const double a = m.bodies[m.theta_joint[j]].joint.reflected_inertia;
    if (a == 0) continue;
    for (SpRowMat::InnerIterator ck(m.C_sparse, j); ck; ++ck)
      for (SpRowMat::InnerIterator ci(m.C_sparse, j); ci; ++ci)
        entries.emplace_back(ck.col(), ci.col(), ck.value() * a * ci.value());
  }
  m.has_armature = !entries.empty();
  m.armature_mass.resize(m.n(), m.n());
  m.armature_mass.setFromTriplets(entries.begin(), entries.end());
  m.armature_mass.makeCompressed();
}

// The terms on a joint of several rates: a free joint's rotor, a damper on each rate.
void compile_rate_terms(Model& m) {
  m.free_rotors.clear();  // (a free or spherical joint is coupled to nothing: its rates are q̇'s)
  m.rate_dampers.clear();
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (J.type == JointType::Free && J.reflected_inertia != 0 && J.idx_v >= 0)
      m.free_rotors.push_back({c.v, J.idx_v, J.reflected_inertia});
    if (J.nv > 1 && J.damping != 0 && J.idx_v >= 0)
      m.rate_dampers.push_back({c.v, J.idx_v, J.nv, J.damping});
  }
}

// Effort limits, on the rates of q that the joints own. A coupled joint's is kept but not
// applied: no τ acts on it directly (simulate says so, sim/recorded_run.hpp).
void compile_effort_limits(Model& m) {
  m.effort_limit = VecX::Constant(m.n(), INFINITY);
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (J.nv == 1) m.effort_limit[c.v] = J.effort_limit;
  }
  m.has_effort_limits = (m.effort_limit.array() < INFINITY).any();
}

// Actuation: every rate of q but those a joint that is not actuated owns (a coupled
// coordinate, owned by no joint, is driven through the joints its coupling moves).
void compile_actuated_rates(Model& m) {
  std::vector<bool> driven(m.n(), true);
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (!J.actuated)
      for (int k = 0; k < J.nv; ++k) driven[c.v + k] = false;
  }
  m.actuated.clear();
  for (int i = 0; i < m.n(); ++i)
    if (driven[i]) m.actuated.push_back(i);
}

}  // namespace

void compile_actuators(Model& m) {
  compile_armature_mass(m);
  compile_rate_terms(m);
  compile_effort_limits(m);
  compile_actuated_rates(m);
}

void actuate_free_joints(Model& m) {
  for (Body& b : m.bodies)
    if (b.joint.type == JointType::Free) b.joint.actuated = true;
  compile_actuators(m);
}

void compile_prescribed(const MechanismSpec& spec, const std::vector<int>& body_of_spec, Model& m) {
  m.prescribed.clear();
  for (std::size_t s = 0; s < spec.bodies.size(); ++s) {
    const JointSpec& js = spec.bodies[s].joint;
    if (!js.prescribed) continue;
    const int b = body_of_spec[s];
    const Joint& J = m.bodies[b].joint;
    int coordinate = -1;
    for (const CoordinateJoint& c : m.coordinate_joints)
      if (c.body == b) coordinate = c.v;
    if (J.nv != 1 || coordinate < 0)
      throw ModelError(js.where + "/prescribed",
                       "only a joint of one rate that is a coordinate of its own (not one that "
                       "follows a coupling) can be prescribed");
    m.prescribed.push_back({coordinate, J.name, *js.prescribed});
  }
}

}  // namespace femdyn
