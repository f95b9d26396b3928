#include "compile/compile_level.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "compile/actuators.hpp"
#include "compile/routes.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

bool has_coupling_law(const MechanismSpec& spec) {
  return std::any_of(spec.couplings.begin(), spec.couplings.end(),
                     [](const CouplingSpec& c) { return c.law != nullptr; });
}

namespace {

// One coupling's arguments (θ indices) and law; a linear coupling becomes a LinearCoupling.
CoupledJoint coupled_joint(const CouplingSpec& c, const std::map<std::string, int>& theta_of,
                           int theta) {
  CoupledJoint j;
  j.theta = theta;
  j.name = c.joint;
  j.where = c.where;
  const auto source = [&](const std::string& name) {
    const auto it = theta_of.find(name);
    if (it == theta_of.end())
      throw ModelError(c.where + "/follows", "unknown or fixed joint " + quoted_text(name));
    return it->second;
  };
  if (c.law) {
    for (const std::string& f : c.follows) j.sources.push_back(source(f));
    if (static_cast<int>(j.sources.size()) != c.law->arity())
      throw ModelError(c.where + "/follows", "the law takes " + std::to_string(c.law->arity()) +
                                                 " joints, " + std::to_string(j.sources.size()) +
                                                 " are named");
    j.law = c.law;
  } else {
    std::vector<double> ratios;
    for (const auto& [name, ratio] : c.terms) {
      j.sources.push_back(source(name));
      ratios.push_back(ratio);
    }
    j.law = std::make_shared<LinearCoupling>(std::move(ratios), c.offset);
  }
  if (j.sources.empty())
    throw ModelError(c.where + "/follows", "names no joint (to fix a joint, make it fixed)");
  return j;
}

// The coupled joints with every joint they follow before them: depth-first with an explicit
// stack (no recursion), cycles reported.
std::vector<CoupledJoint> dependency_order(std::map<int, CoupledJoint> coupled, const Model& m) {
  std::vector<CoupledJoint> order;
  std::map<int, int> state;  // θ -> 1 in progress, 2 done
  for (const auto& [t0, unused] : coupled) {
    std::vector<std::pair<int, std::size_t>> stack = {{t0, 0}};
    while (!stack.empty()) {
      auto& [t, k] = stack.back();
      const auto it = coupled.find(t);
      if (it == coupled.end() || state[t] == 2) {  // a coordinate, or resolved
        stack.pop_back();
        continue;
      }
      state[t] = 1;
      if (k == it->second.sources.size()) {
        state[t] = 2;
        order.push_back(it->second);
        stack.pop_back();
        continue;
      }
      const int s = it->second.sources[k++];
      if (state[s] == 1)
        throw ModelError(coupled.at(s).where, "couplings form a cycle through joint '" +
                                                  m.bodies[m.theta_joint[s]].joint.name + "'");
      stack.emplace_back(s, 0);
    }
  }
  return order;
}

// A one-argument law must be defined over the whole range of the joint it follows (its
// limits, or a full turn without): a four-bar that cannot assemble or locks is refused.
void check_range(const CoupledJoint& j, const Model& m) {
  if (j.sources.size() != 1) return;
  const Joint& in = m.bodies[m.theta_joint[j.sources[0]]].joint;
  const bool limited = std::isfinite(in.lower) && std::isfinite(in.upper);
  const double lo = limited ? in.lower : -std::numbers::pi,
               hi = limited ? in.upper : std::numbers::pi;
  if (const auto at = j.law->lock_angle(lo, hi))
    throw ModelError(j.where, "the linkage of joint '" + j.name + "' cannot assemble or locks at " +
                                  in.name + " = " + format_number(*at) + " rad, within " +
                                  (limited ? "its limits [" : "a full turn [") + format_number(lo) +
                                  ", " + format_number(hi) + "]" +
                                  (limited ? "" : " (give " + in.name + " limits)"));
}

}  // namespace

namespace {

// The coupled joints by θ index, each checked (a known joint, coupled once).
std::map<int, CoupledJoint> coupled_joints(const std::vector<CouplingSpec>& couplings,
                                           const Model& m) {
  std::map<std::string, int> theta_of;  // joint name -> θ index
  for (int t = 0; t < m.n_theta(); ++t) theta_of[m.bodies[m.theta_joint[t]].joint.name] = t;
  std::map<int, CoupledJoint> coupled;
  for (const CouplingSpec& c : couplings) {
    const auto it = theta_of.find(c.joint);
    if (it == theta_of.end())
      throw ModelError(c.where + "/joint", "unknown or fixed joint " + quoted_text(c.joint));
    if (coupled.count(it->second))
      throw ModelError(c.where + "/joint", "joint '" + c.joint + "' is coupled twice");
    coupled.emplace(it->second, coupled_joint(c, theta_of, it->second));
  }
  return coupled;
}

// The level's coordinates: the joints no coupling sets, laid out in q as the model's
// coordinates (their names and Model::coordinate_joints), and the coupled joints in dependency
// order, each law checked over its input's range.
std::shared_ptr<CouplingLevel> level_coordinates(Model& m, std::map<int, CoupledJoint> coupled) {
  auto level = std::make_shared<CouplingLevel>();
  level->n_theta = m.n_theta();
  level->n_theta_q = m.n_theta_q;
  m.coordinate_names.clear();
  m.coordinate_joints.clear();
  m.configuration_names.clear();
  level->theta_q.assign(m.n_theta(), -1);
  for (int t = 0; t < m.n_theta(); ++t) {
    const Joint& J = m.bodies[m.theta_joint[t]].joint;
    if (is_flat(J)) level->theta_q[t] = J.idx_q + (t - J.idx_v);
    if (coupled.count(t)) continue;
    if (t == J.idx_v) m.coordinate_joints.push_back({m.theta_joint[t], 0, level->n});
    level->coordinate_theta.push_back(t);
    m.coordinate_names.push_back(J.nv == 1 ? J.name : J.name + "." + rate_name(J, t - J.idx_v));
    ++level->n;
  }
  lay_out_coordinates(m);
  for (const CoordinateJoint& c : m.coordinate_joints)
    for (int k = 0; k < m.bodies[c.body].joint.nq; ++k)
      level->configuration_theta.push_back(m.bodies[c.body].joint.idx_q + k);
  level->coupled = dependency_order(std::move(coupled), m);
  if (level->n == 0) throw ModelError(m.where, "every joint is coupled: there is no coordinate");
  for (const CoupledJoint& j : level->coupled) {
    level->largest_arity = std::max(level->largest_arity, static_cast<int>(j.sources.size()));
    check_range(j, m);
  }
  return level;
}

// C and θ0: g's linearisation at q_ref (each coordinate at 0, or its nearest limit), for the
// reports and structure analyses only; a dependence with zero slope there is stored as 1.
void linearise_level(Model& m, const CouplingLevel& level) {
  const int n = level.n, nt = level.n_theta;
  const VecX q_ref = reference_posture(m);  // (by m.coordinate_joints, already the level's)
  CouplingLevelState s(level);
  const VecX zero = VecX::Zero(n);
  if (!evaluate_level(level, q_ref, zero, zero, s))
    throw ModelError(level.coupled[s.failed].where,
                     "the law of joint '" + level.coupled[s.failed].name +
                         "' is not defined at the reference posture (every coordinate at 0 or "
                         "its nearest limit)");
  std::vector<std::vector<bool>> depends(nt, std::vector<bool>(n, false));
  for (int a = 0; a < n; ++a) depends[level.coordinate_theta[a]][a] = true;
  for (const CoupledJoint& j : level.coupled)
    for (int src : j.sources)
      for (int a = 0; a < n; ++a) depends[j.theta][a] = depends[j.theta][a] || depends[src][a];
  std::vector<Eigen::Triplet<double>> entries;
  for (int t = 0; t < nt; ++t)
    for (int a = 0; a < n; ++a)
      if (depends[t][a]) entries.emplace_back(t, a, s.G(t, a) != 0 ? s.G(t, a) : 1.0);
  m.C.resize(nt, n);
  m.C.setFromTriplets(entries.begin(), entries.end());
  m.C_sparse = m.C;
  m.theta0 = VecX::Zero(nt);  // θ0 = g(q_ref) − G q_ref on the one-coordinate joints
  for (int t = 0; t < nt; ++t)
    if (level.theta_q[t] >= 0) {
      m.theta0[t] = s.theta[level.theta_q[t]];
      for (int a = 0; a < n; ++a)
        if (const int i = level.theta_q[level.coordinate_theta[a]]; i >= 0 && s.G(t, a) != 0)
          m.theta0[t] -= s.G(t, a) * s.theta[i];
    }
}

}  // namespace

Model with_coupling_level(Model tree, const std::vector<CouplingSpec>& couplings) {
  // The law model's bodies and elements are its tree's; its coordinates differ.
  Model m = tree.copy();
  std::shared_ptr<CouplingLevel> level = level_coordinates(m, coupled_joints(couplings, m));
  linearise_level(m, *level);
  compile_actuators(m);
  m.identity_coupling = false;
  configuration_coupling(m);
  m.free_rotors.clear();  // (its tree's equations add these: core/coupling_chain)
  m.rate_dampers.clear();
  m.coupling_level = std::move(level);
  m.tree = std::make_shared<const Model>(std::move(tree));
  choose_routes(m);  // the law chain
  return m;
}

double span_length(const ElementEntry& e, const Workspace& ws) {
  const auto nodes = e.element->nodes();
  const auto world = [&](int l) {
    const BodyState& B = ws.body[e.node_body[l]];
    return Vec3(B.p + B.R * nodes[l].position);
  };
  return (world(0) - world(1)).norm();
}

void check_rigid_spans(const Model& m) {
  const bool any = std::any_of(m.elements.begin(), m.elements.end(),
                               [](const ElementEntry& e) { return e.spans; });
  if (!any) return;
  Workspace ws(m);
  VecX q(m.n_q());
  std::mt19937 rng(12345);
  const VecX zero = VecX::Zero(m.n());
  std::vector<double> L0;
  for (int k = 0; k <= 64; ++k) {
    q = k == 0 ? reference_posture(m) : random_posture(m, rng);
    propagate(m, ws, q, zero, {.jacobian = false, .bias = false});
    std::size_t s = 0;
    for (const ElementEntry& e : m.elements) {
      if (!e.spans || e.node_body.size() != 2) continue;
      const double L = span_length(e, ws);
      if (k == 0) {
        L0.push_back(L);
        continue;
      }
      const double change = L - L0[s++];
      if (std::abs(change) > 1e-9 * L0[s - 1] + 1e-12) {
        std::string at;
        for (int a = 0; a < m.n_q(); ++a)
          at += (a ? ", " : "") + m.configuration_names[a] + " = " + format_number(q[a]);
        throw ModelError(e.where, std::string(e.element->type_name()) +
                                      " spanning two bodies does not keep its length: " +
                                      format_number(L0[s - 1]) + " m at the reference posture, " +
                                      format_number(L) + " m at " + at + " (a change of " +
                                      format_number(change) + " m)");
      }
    }
  }
}

}  // namespace femdyn
