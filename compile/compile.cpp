// compile(): MechanismSpec -> Model. Tree order and joints, the coupling level θ = C q + θ0,
// then the node level and the correlation table (compile/correlation.cpp).
#include "compile/compile.hpp"

#include <cmath>
#include <map>
#include <set>
#include <utility>

#include "compile/actuators.hpp"
#include "compile/bar_damping.hpp"
#include "compile/compile_level.hpp"
#include "compile/correlation.hpp"
#include "compile/loops.hpp"
#include "compile/routes.hpp"
#include "core/dynamics/body_inertia.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/rotation.hpp"
#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/model.hpp"
#include "core/model/names.hpp"

namespace femdyn {
namespace {

// Each body's spec index by name; the names checked (not empty, not 'world', unique).
std::map<std::string, int> body_index(const MechanismSpec& spec) {
  std::map<std::string, int> index;
  for (std::size_t i = 0; i < spec.bodies.size(); ++i) {
    const BodySpec& b = spec.bodies[i];
    if (b.name.empty()) throw ModelError(b.where, "body has an empty name");
    check_name(b.name, b.where + "/name", "body name");
    check_name(b.joint.name, b.joint.where + "/name", "joint name");
    if (b.name == "world") throw ModelError(b.where, "'world' is reserved for the ground");
    if (!index.emplace(b.name, static_cast<int>(i)).second)
      throw ModelError(b.where, "duplicate body name '" + b.name + "'");
  }
  return index;
}

// children[k + 1]: the bodies hanging from body k (children[0]: from the world), in file order.
std::vector<std::vector<int>> children_of(const MechanismSpec& spec,
                                          const std::map<std::string, int>& index) {
  std::vector<std::vector<int>> children(spec.bodies.size() + 1);
  for (std::size_t i = 0; i < spec.bodies.size(); ++i) {
    const BodySpec& b = spec.bodies[i];
    if (b.parent != "world" && !index.count(b.parent))
      throw ModelError(b.where + "/parent", "unknown parent body " + quoted_text(b.parent));
    if (b.parent == b.name) throw ModelError(b.where + "/parent", "body is its own parent");
    children[b.parent == "world" ? 0 : index.at(b.parent) + 1].push_back(static_cast<int>(i));
  }
  return children;
}

// Depth-first, parents before children, siblings in file order; an explicit stack (not
// recursion), so that a chain of any length cannot overflow the call stack.
std::vector<int> depth_first(const std::vector<std::vector<int>>& children) {
  std::vector<int> order;
  order.reserve(children.size() - 1);
  std::vector<std::pair<int, std::size_t>> stack = {{0, 0}};  // (children slot, next child)
  while (!stack.empty()) {
    auto& [slot, next] = stack.back();
    if (next == children[slot].size()) {
      stack.pop_back();
      continue;
    }
    const int c = children[slot][next++];
    order.push_back(c);
    stack.emplace_back(c + 1, 0);
  }
  return order;
}

// Bodies in depth-first order from the world, children in file order. Returns spec indices.
std::vector<int> tree_order(const MechanismSpec& spec) {
  const std::vector<int> order = depth_first(children_of(spec, body_index(spec)));
  if (order.size() != spec.bodies.size()) {
    std::set<int> reached(order.begin(), order.end());
    for (std::size_t i = 0; i < spec.bodies.size(); ++i)
      if (!reached.count(static_cast<int>(i)))
        throw ModelError(spec.bodies[i].where + "/parent",
                         "body '" + spec.bodies[i].name +
                             "' is not connected to the world (its parents form a cycle)");
  }
  return order;
}

// What the joint's type reads beyond its axis (core/joints/parameters.hpp): a second axis (unit,
// normal to the first) for a type of two axes, and its own numbers; another type's are refused.
void check_joint_parameters(const JointSpec& js, Joint& j) {
  const JointParameters type = joint_parameters(js.type);
  if (type.axes == JointAxes::Two) {
    if (!js.axis2)
      throw ModelError(js.where + "/axis2", "a " + std::string(joint_type_name(js.type)) +
                                                " joint needs its second axis");
    check_magnitude(*js.axis2, js.where + "/axis2", "axis2");
    if (!(js.axis2->norm() > 1e-12)) throw ModelError(js.where + "/axis2", "axis2 is zero");
    j.axis2 = js.axis2->normalized();
    if (std::abs(j.axis2.dot(j.axis)) > 1e-9)
      throw ModelError(js.where + "/axis2", "a " + std::string(joint_type_name(js.type)) +
                                                " joint's two axes must be normal to each other");
  } else if (js.axis2) {
    throw ModelError(js.where + "/axis2", joint_axis2_refusal());
  }
  for (const auto& [key, value] : js.scalars) {
    const JointScalar* s = joint_scalar(js.type, key);
    if (!s) throw ModelError(js.where + "/" + key, joint_scalar_refusal(key));
    check_magnitude(value, js.where + "/" + key, key.c_str());
    j.*(s->value) = value;
  }
}

// An origin given as a quaternion (w, x, y, z): finite, not zero, normalised.
Mat3 quaternion_origin(const Eigen::Vector4d& w, const std::string& where) {
  for (int k = 0; k < 4; ++k) check_magnitude(w[k], where, "origin quat");
  if (!(w.norm() > 1e-12)) throw ModelError(where, "origin quat is zero");
  const Eigen::Vector4d u = w.normalized();
  return quaternion_rotation(u.data());
}

// The joint frame in its parent (xyz and rpy or a quaternion) and its unit axis.
void place_joint(const JointSpec& js, Joint& j) {
  check_magnitude(js.xyz, js.where + "/origin/xyz", "origin xyz");
  check_magnitude(js.rpy, js.where + "/origin/rpy", "origin rpy");
  j.p_pj = js.xyz;
  j.R_pj =
      js.quat ? quaternion_origin(*js.quat, js.where + "/origin/quat") : rpy_to_rotation(js.rpy);
  if (js.type != JointType::Fixed) {
    check_magnitude(js.axis, js.where + "/axis", "axis");
    const double norm = js.axis.norm();
    if (!(norm > 1e-12)) throw ModelError(js.where + "/axis", "axis is zero");
    j.axis = js.axis / norm;
  }
}

// The spring, damper, limits and initial value: checked, then copied.
void compile_joint_terms(const JointSpec& js, Joint& j) {
  for (auto [x, what] :
       {std::pair{js.stiffness, "stiffness"}, {js.rest, "rest"}, {js.damping, "damping"}})
    check_magnitude(x, js.where, what);
  // A damper −c on each rate is isotropic on a spherical or free joint (the same in any axes,
  // as MuJoCo's dof_damping); on a universal or planar joint's mixed rates it would not be.
  const bool damped_rates = j.type == JointType::Spherical || j.type == JointType::Free;
  if (j.nv != 1 && (js.stiffness != 0 || (js.damping != 0 && !damped_rates) ||
                    std::isfinite(js.lower) || std::isfinite(js.upper)))
    throw ModelError(js.where, std::string("a ") + std::string(joint_type_name(j.type)) +
                                   " joint takes no spring, damper or limits (only joints of "
                                   "one coordinate do, and a spherical or free joint a damper)");
  if (js.stiffness < 0) throw ModelError(js.where + "/spring", "negative stiffness");
  if (js.damping < 0) throw ModelError(js.where + "/damping", "negative damping");
  if (std::isnan(js.lower) || std::isnan(js.upper) || js.lower > js.upper)
    throw ModelError(js.where + "/limits", "joint limits are NaN or lower > upper");
  check_magnitude(js.initial, js.where + "/initial", "initial");
  if (js.initial != 0 && j.nq != 1)
    throw ModelError(js.where + "/initial", "is the coordinate of a joint of one: this " +
                                                std::string(joint_type_name(j.type)) +
                                                " joint has " + std::to_string(j.nq));
  check_magnitude(js.sample_range, js.where + "/sample_range", "sample_range");
  if (js.sample_range != 0 && j.nv != 1)
    throw ModelError(js.where + "/sample_range", "is the half range of a joint of one coordinate");
  j.sample_range = js.sample_range;
  j.stiffness = js.stiffness;
  j.rest = js.rest;
  j.initial = js.initial;
  j.damping = js.damping;
  j.lower = js.lower;
  j.upper = js.upper;
}

Joint compile_joint(const JointSpec& js, const std::string& body_name) {
  Joint j;
  j.name = js.name.empty() ? body_name : js.name;
  j.type = js.type;
  j.where = js.where;
  place_joint(js, j);
  check_joint_parameters(js, j);
  prepare_joint(j);
  compile_joint_terms(js, j);
  compile_actuator(js, j);
  return j;
}

// Every body's own frame, then the named frames of the spec (names unique among all).
void compile_frames(const MechanismSpec& spec, Model& m) {
  std::map<std::string, int> body_of;
  for (int b = 0; b < static_cast<int>(m.bodies.size()); ++b) {
    body_of.emplace(m.bodies[b].name, b);
    m.frames.push_back({m.bodies[b].name, b, Mat3::Identity(), Vec3::Zero()});
  }
  std::set<std::string> names;
  for (const Body& b : m.bodies) names.insert(b.name);
  for (const FrameSpec& f : spec.frames) {
    check_name(f.name, f.where + "/name", "frame name");
    if (!names.insert(f.name).second)
      throw ModelError(f.where + "/name", "frame name " + quoted_text(f.name) +
                                              " is taken (by a body or another frame)");
    const auto it = body_of.find(f.body);
    if (it == body_of.end())
      throw ModelError(f.where + "/body", "unknown body " + quoted_text(f.body));
    check_magnitude(f.xyz, f.where + "/xyz", "xyz");
    check_magnitude(f.rpy, f.where + "/rpy", "rpy");
    m.frames.push_back({f.name, it->second, rpy_to_rotation(f.rpy), f.xyz});
  }
}

// Each flexible bar's centreline, its stations by body index.
void compile_bars(const MechanismSpec& spec, Model& m) {
  if (spec.bars.empty()) return;
  std::map<std::string, int> body_of;
  for (int b = 0; b < static_cast<int>(m.bodies.size()); ++b) body_of.emplace(m.bodies[b].name, b);
  for (const BarSpec& bar : spec.bars) {
    BarCentreline& c = m.bars.emplace_back(BarCentreline{bar.name, {}, bar.radius});
    for (const std::string& station : bar.stations) {
      const auto it = body_of.find(station);
      if (it == body_of.end())  // (the bar's own bodies: a builder's mistake)
        throw ModelError(bar.where, "unknown body " + quoted_text(station));
      c.stations.push_back(it->second);
    }
  }
}

// Couplings join joints of one rate (a coupled multi-rate joint would need a law per rate).
void check_one_rate(const Model& m, int t, const std::string& where) {
  const Joint& j = m.bodies[m.theta_joint[t]].joint;
  if (j.nv != 1)
    throw ModelError(where, "joint '" + j.name + "' is " + std::string(joint_type_name(j.type)) +
                                " (" + std::to_string(j.nv) +
                                " rates): couplings join joints of one coordinate");
}

using ThetaOf = std::map<std::string, int>;          // joint name -> its first rate in θ
using Coupled = std::map<int, const CouplingSpec*>;  // θ index -> its coupling

// Each coupling checked: a joint of one rate coupled once, following joints of one rate.
Coupled checked_couplings(const MechanismSpec& spec, const Model& m, const ThetaOf& theta_of) {
  Coupled coupled;
  for (const CouplingSpec& c : spec.couplings) {
    auto it = theta_of.find(c.joint);
    if (it == theta_of.end())
      throw ModelError(c.where + "/joint", "unknown or fixed joint " + quoted_text(c.joint));
    check_one_rate(m, it->second, c.where + "/joint");
    if (!coupled.emplace(it->second, &c).second)
      throw ModelError(c.where + "/joint", "joint '" + c.joint + "' is coupled twice");
    check_magnitude(c.offset, c.where + "/offset", "offset");
    if (c.terms.empty())
      throw ModelError(c.where + "/follows", "names no joint (to fix a joint, make it fixed)");
    for (const auto& [name, ratio] : c.terms) {
      if (!theta_of.count(name))
        throw ModelError(c.where + "/follows", "unknown or fixed joint " + quoted_text(name));
      check_one_rate(m, theta_of.at(name), c.where + "/follows");
      check_magnitude(ratio, c.where + "/ratio", "ratio");
    }
  }
  return coupled;
}

// The joints no coupling sets are the coordinates q, in tree order: q_of[t] for each, -1 for a
// coupled one; their names and Model::coordinate_joints.
std::vector<int> number_coordinates(Model& m, const Coupled& coupled) {
  const int nt = m.n_theta();
  std::vector<int> q_of(nt, -1);
  for (int t = 0; t < nt; ++t)
    if (!coupled.count(t)) {
      q_of[t] = static_cast<int>(m.coordinate_names.size());
      const Joint& j = m.bodies[m.theta_joint[t]].joint;
      if (t == j.idx_v) m.coordinate_joints.push_back({m.theta_joint[t], 0, q_of[t]});
      m.coordinate_names.push_back(j.nv == 1 ? j.name : j.name + "." + rate_name(j, t - j.idx_v));
    }
  return q_of;
}

// How far coupling_rows has got with each joint.
enum class RowState { New, InProgress, Done };

// Joint t0's row of C and θ0, after the rows of the joints it follows, depth-first with an
// explicit stack (a chain of couplings of any length cannot overflow the call stack); a cycle
// is reported at a joint on it.
void coupling_row(int t0, Model& m, const Coupled& coupled, const ThetaOf& theta_of,
                  const std::vector<int>& q_of, std::vector<RowState>& state,
                  std::vector<std::map<int, double>>& rows) {
  std::vector<std::pair<int, std::size_t>> stack = {{t0, 0}};  // (joint, next term)
  while (!stack.empty()) {
    const auto [t, k] = stack.back();
    if (k == 0 && state[t] == RowState::New) {
      state[t] = RowState::InProgress;
      if (q_of[t] >= 0) {  // a coordinate: its own row
        rows[t][q_of[t]] = 1.0;
        state[t] = RowState::Done;
        stack.pop_back();
        continue;
      }
      m.theta0[t] = coupled.at(t)->offset;
    }
    const auto& terms = coupled.at(t)->terms;
    if (k == terms.size()) {
      state[t] = RowState::Done;
      stack.pop_back();
      continue;
    }
    const auto& [name, ratio] = terms[k];
    const int f = theta_of.at(name);
    if (state[f] == RowState::InProgress)
      throw ModelError(coupled.at(f)->where, "couplings form a cycle through joint '" +
                                                 m.bodies[m.theta_joint[f]].joint.name + "'");
    if (state[f] == RowState::New) {
      stack.emplace_back(f, 0);
      continue;
    }
    for (const auto& [a, c] : rows[f]) rows[t][a] += ratio * c;  // θ_t += ratio θ_f
    m.theta0[t] += ratio * m.theta0[f];
    ++stack.back().second;
  }
}

// C row by row (O(non-zeros), not nθ × n) and θ0.
std::vector<std::map<int, double>> coupling_rows(Model& m, const Coupled& coupled,
                                                 const ThetaOf& theta_of,
                                                 const std::vector<int>& q_of) {
  const int nt = m.n_theta();
  std::vector<std::map<int, double>> rows(nt);
  m.theta0 = VecX::Zero(nt);
  std::vector<RowState> state(nt, RowState::New);
  for (int t0 = 0; t0 < nt; ++t0)
    if (state[t0] != RowState::Done) coupling_row(t0, m, coupled, theta_of, q_of, state, rows);
  return rows;
}

// The coupling level: C (nθ x n) and θ0 from the couplings; the remaining movable joints,
// in tree order, are the generalized coordinates q.
void compile_coupling(const MechanismSpec& spec, Model& m) {
  ThetaOf theta_of;
  for (std::size_t t = m.theta_joint.size(); t-- > 0;)  // a joint's first rate
    theta_of[m.bodies[m.theta_joint[t]].joint.name] = static_cast<int>(t);
  const Coupled coupled = checked_couplings(spec, m, theta_of);
  const std::vector<int> q_of = number_coordinates(m, coupled);
  const int nt = m.n_theta(), n = static_cast<int>(m.coordinate_names.size());
  if (nt == 0) throw ModelError(m.where, "has no movable joint: there is no motion to compute");
  // (n = 0 with nθ > 0 would need every joint coupled, i.e. a cycle: reported below.)
  const std::vector<std::map<int, double>> rows = coupling_rows(m, coupled, theta_of, q_of);
  // The hot path's form of C (core/kinematics/coupling.hpp).
  std::vector<Eigen::Triplet<double>> entries;
  bool identity = nt == n && m.theta0.isZero(0);
  for (int t = 0; t < nt; ++t)
    for (const auto& [a, c] : rows[t])
      if (c != 0) {
        entries.emplace_back(t, a, c);
        identity = identity && a == t && c == 1.0;
      }
  m.C.resize(nt, n);
  m.C.setFromTriplets(entries.begin(), entries.end());
  m.identity_coupling = identity && static_cast<int>(entries.size()) == n;
  m.C_sparse = m.C;
}

}  // namespace

// Each coordinate joint's address in q (its address in v is set with C), and the names of q's
// entries: a joint's name for one coordinate, else "name.coordinate".
void lay_out_coordinates(Model& m) {
  for (CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    c.q = m.n_q();
    for (int k = 0; k < J.nq; ++k)
      m.configuration_names.push_back(J.nq == 1 ? J.name : J.name + "." + coordinate_name(J, k));
  }
}

// θ = C_q q + θ0_q (Model::C_configuration): C's rows with each coordinate's column moved to its
// entry of q (a one-rate joint's coordinate), and a joint with nq ≠ nv the identity on its own.
void configuration_coupling(Model& m) {
  std::vector<int> q_of_v(m.n(), -1);  // a flat joint's rate -> its coordinate in q
  std::vector<int> owner(m.bodies.size(), -1);
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    owner[c.body] = c.q;
    if (is_flat(J))
      for (int k = 0; k < J.nv; ++k) q_of_v[c.v + k] = c.q + k;
  }
  std::vector<Eigen::Triplet<double>> entries;
  m.theta0_configuration = VecX::Zero(m.n_theta_q);
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    if (owner[b] >= 0 && !is_flat(J)) {
      for (int k = 0; k < J.nq; ++k) entries.emplace_back(J.idx_q + k, owner[b] + k, 1.0);
      continue;
    }
    for (int k = 0; k < J.nv; ++k) {  // flat: θ_q = θ, row by row
      m.theta0_configuration[J.idx_q + k] = m.theta0[J.idx_v + k];
      for (SpRowMat::InnerIterator it(m.C_sparse, J.idx_v + k); it; ++it)
        entries.emplace_back(J.idx_q + k, q_of_v[it.col()], it.value());
    }
  }
  m.C_configuration.resize(m.n_theta_q, m.n_q());
  m.C_configuration.setFromTriplets(entries.begin(), entries.end());
}

namespace {

// The checks of a finished model, run once its routes are chosen (they evaluate it): its
// spanning elements keep their lengths, and M^s is positive definite (on the tree of a law
// model, whose coordinates move freely).
void check_model(const Model& m, const CompileOptions& options) {
  check_rigid_spans(m);
  if (options.check_mass) check_mass_matrix(m.tree ? *m.tree : m);
}

}  // namespace

Model compile(MechanismSpec spec, const CompileOptions& options) {
  const bool law = has_coupling_law(spec);
  // (the law chain reduces the tree's equations through θ = g(q); loops and springs act on
  // the tree's own coordinates)
  if (law && !spec.constraints.empty())
    throw ModelError(spec.where + "/constraints",
                     "a model with a coupling law cannot also have constraints (close the loop "
                     "either by the law or by constraints)");
  if (law && !spec.springs.empty())
    throw ModelError(spec.where + "/springs",
                     "a model with a coupling law cannot also have two-point springs");
  const std::vector<CouplingSpec> couplings =
      law ? std::exchange(spec.couplings, {}) : std::vector<CouplingSpec>{};
  const std::vector<BarSpec> bars = spec.bars;
  Model m = compile_tree(std::move(spec), options);
  if (law) m = with_coupling_level(std::move(m), couplings);
  compile_bar_damping(bars, m);  // (M^s at rest: the routes are chosen)
  check_model(m, options);
  return m;
}

namespace {

// The spec's own checks: its name, gravity and number of bodies.
void compile_header(const MechanismSpec& spec, Model& m) {
  m.name = spec.name;
  m.where = spec.where.size() >= 2 ? spec.where.substr(0, spec.where.size() - 2) : spec.where;
  check_magnitude(spec.gravity,
                  spec.gravity_where.empty() ? spec.where + "/gravity" : spec.gravity_where,
                  "gravity");
  check_name(spec.name, spec.where + "/name", "model name");
  if (static_cast<long long>(spec.bodies.size()) > kMaxBodies)
    throw ModelError(spec.where + "/bodies", too_many_bodies_text(spec.bodies.size()));
  m.gravity = spec.gravity;
  if (spec.bodies.empty()) throw ModelError(spec.where + "/bodies", "the model has no bodies");
}

// The bodies in tree order with their joints, their addresses in θ and θ̇ (they differ after
// a joint with nq ≠ nv) and each rate's parent rate. Returns each spec body's index in m.bodies.
std::vector<int> compile_bodies(const MechanismSpec& spec, Model& m) {
  const std::vector<int> order = tree_order(spec);
  std::vector<int> body_of_spec(spec.bodies.size());
  std::set<std::string> joint_names;
  std::map<std::string, int> compiled;  // body name -> index in m.bodies
  std::vector<int> last_rate;           // body -> the last rate on its path, -1 for none
  for (std::size_t k = 0; k < order.size(); ++k) {
    const BodySpec& bs = spec.bodies[order[k]];
    body_of_spec[order[k]] = static_cast<int>(k);
    Body b{.name = bs.name, .joint = compile_joint(bs.joint, bs.name), .where = bs.where};
    if (!joint_names.insert(b.joint.name).second)
      throw ModelError(bs.joint.where + "/name", "duplicate joint name '" + b.joint.name + "'");
    b.parent = bs.parent == "world" ? -1 : compiled.at(bs.parent);  // (placed before: tree order)
    compiled.emplace(bs.name, static_cast<int>(k));
    last_rate.push_back(b.parent >= 0 ? last_rate[b.parent] : -1);
    if (moves(b.joint)) {
      b.joint.idx_q = m.n_theta_q;
      m.n_theta_q += b.joint.nq;
      b.joint.idx_v = static_cast<int>(m.theta_joint.size());
      for (int r = 0; r < b.joint.nv; ++r) {
        m.rate_parent.push_back(last_rate.back());
        last_rate.back() = static_cast<int>(m.theta_joint.size());
        m.theta_joint.push_back(static_cast<int>(k));
      }
    }
    m.bodies.push_back(std::move(b));
  }
  return body_of_spec;
}

}  // namespace

Model compile_tree(MechanismSpec spec, const CompileOptions& options) {
  Model m;
  compile_header(spec, m);
  const std::vector<int> body_of_spec = compile_bodies(spec, m);
  compile_frames(spec, m);
  compile_bars(spec, m);
  compile_coupling(spec, m);
  lay_out_coordinates(m);
  configuration_coupling(m);
  compile_actuators(m);
  compile_prescribed(spec, body_of_spec, m);
  compile_loops(spec, m);
  provisional_routes(m);  // (the node level samples the kinematics)
  build_node_level(spec, body_of_spec, m);
  condense_body_inertia(m);
  choose_routes(m, options.routes);
  return m;
}

}  // namespace femdyn
