#include "validation/validate_loops.hpp"

#include <algorithm>
#include <cmath>

#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/model/errors.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn::validation {

namespace {

// The body whose 1-DOF joint has θ index `theta`.
int body_of_theta(const Model& m, int theta) {
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].joint.idx_q == theta) return static_cast<int>(b);
  throw ModelError(m.where, "a gear names a joint the Simbody twin cannot find");
}

TwinConstraint twin_constraint(const Model& m, const LoopConstraint& c) {
  TwinConstraint t;
  t.name = c.name;
  t.body_a = c.a.body, t.body_b = c.b.body;
  t.R_a = c.a.R, t.R_b = c.b.R;
  t.p_a = c.a.p, t.p_b = c.b.p;
  switch (c.type) {
    case ConstraintType::Ball:
    case ConstraintType::PointOnLine:
    case ConstraintType::PointOnPlane:
      // Rows E R_Bᵀ d along B's axes: none (a ball in space), the two ⟂ a line (A's point on
      // the line through B's point), or a plane's normal.
      if (c.axes.empty()) {
        t.type = TwinConstraint::Type::Ball;
      } else if (c.axes.size() == 2) {
        t.type = TwinConstraint::Type::PointOnLine;
        t.direction = c.b.R * c.axes[0].cross(c.axes[1]).normalized();
      } else if (c.axes.size() == 1) {
        t.type = TwinConstraint::Type::PointInPlane;
        t.direction = c.b.R * c.axes[0].normalized();
      } else {
        throw ModelError(c.where, "the Simbody twin has no constraint of " +
                                      std::to_string(c.axes.size()) + " rows along axes");
      }
      break;
    case ConstraintType::Weld:
      t.type = TwinConstraint::Type::Weld;
      break;
    case ConstraintType::Distance:
      t.type = TwinConstraint::Type::Rod;
      t.length = c.length;
      break;
    case ConstraintType::Gear:
      t.type = TwinConstraint::Type::Gear;
      t.bodies.push_back(body_of_theta(m, c.joint));
      for (const auto& [theta, ratio] : c.terms) {
        t.bodies.push_back(body_of_theta(m, theta));
        t.ratios.push_back(ratio);
      }
      t.offset = c.offset;
      break;
  }
  return t;
}

void accumulate(QuantityError& e, const VecX& femdyn, const VecX& simbody, double scale) {
  const double d = max_abs(femdyn - simbody);
  e.max_abs = std::max(e.max_abs, d);
  e.max_rel = std::max(e.max_rel, scale > 0 ? d / scale : d);
}

// The mechanism's size for the closure errors: the largest attachment offset or rod length.
double loop_size(const Model& m) {
  double L = 0;
  for (const LoopConstraint& c : m.constraints)
    L = std::max({L, c.a.p.norm(), c.b.p.norm(), c.length});
  return L > 0 ? L : 1;
}

}  // namespace

// (validate_loops.hpp)
bool assembled_state(const Model& m, std::mt19937& rng, double qd_scale, VecX& q, VecX& qd,
                     std::string& why) {
  const double step = 0.3 / std::sqrt(static_cast<double>(std::max(m.n(), 1)));
  for (int attempt = 0; attempt < 2; ++attempt) {
    q = attempt == 0 ? integrate_posture(m, neutral_posture(m), random_uniform(m.n(), step, rng))
                     : random_posture(m, rng);
    qd = random_uniform(m.n(), qd_scale, rng);
    const StateAssembly s = assemble_state(m, q, qd);
    if (s.assembly.status.ok) return true;
    why = s.assembly.status.message;
  }
  return false;
}

void add_constraints_and_springs(const Model& m, TwinModel& t) {
  for (const LoopConstraint& c : m.constraints) t.constraints.push_back(twin_constraint(m, c));
  for (const TwoPointSpring& s : m.springs)
    t.springs.push_back({s.a.body, s.b.body, s.a.p, s.b.p, s.stiffness, s.rest_length, s.damping});
}

bool consistent_state(const Model& m, VecX& q0, VecX& qd0, std::string& why) {
  // Of the two assembled candidates, the one whose Φ_q is farther from losing rank
  // (σ_min/σ_max of its non-redundant part): a random posture can assemble into a mode near a
  // dead point, where no integrator gets far.
  double best = -1;
  VecX q_best, qd_best;
  Workspace ws(m);
  ConstraintKinematics k(m);
  for (int attempt = 0; attempt < 2; ++attempt) {
    VecX q = attempt == 0 ? q0 : neutral_posture(m), qd = qd0;
    const StateAssembly s = assemble_state(m, q, qd);
    if (!s.assembly.status.ok) {
      why = s.assembly.status.message;
      continue;
    }
    constraint_kinematics(m, ws, q, qd, k);
    const VecX sigma = Eigen::JacobiSVD<MatX>(k.J).singularValues();
    const int rank = std::max(s.assembly.rank, 1);
    const double ratio = sigma[0] > 0 ? sigma[rank - 1] / sigma[0] : 0;
    if (ratio > best) best = ratio, q_best = q, qd_best = qd;
  }
  if (best < 0) return false;
  q0 = q_best, qd0 = qd_best;
  return true;
}

LoopRows compare_loops(const Model& m, SimbodyTwin& twin, const ValidationOptions& o,
                       double tolerance) {
  LoopRows r;
  r.qdd = {"constrained qdd", 0, 0, tolerance};
  r.force = {"constraint forces", 0, 0, tolerance};
  r.closure = {"closure", 0, 0, tolerance};
  Workspace ws(m);
  LoopWorkspace lws(m);
  std::mt19937 rng(o.seed + 15485863);  // apart from the tree's states
  const double L = loop_size(m);
  int compared = 0;
  std::string why;
  for (int k = 0; k < o.states; ++k) {
    VecX q, qd;
    if (!assembled_state(m, rng, o.qd_scale, q, qd, why)) continue;
    const VecX tau = random_uniform(m.n(), o.tau_scale, rng);
    const Status st = constrained_forward_dynamics(m, ws, lws, q, qd, tau, 0);
    TwinLoopDynamics s;
    try {
      s = twin.loop_dynamics(q, qd, tau);
    } catch (const std::exception& e) {
      r.failure = std::string("the closed mechanism: ") + e.what();
      return r;
    }
    ++compared;
    r.closure.max_abs = std::max({r.closure.max_abs, s.position_error, s.velocity_error});
    r.closure.max_rel = std::max({r.closure.max_rel, s.position_error / L,
                                  s.velocity_error / (L * std::max(1.0, max_abs(qd)))});
    if (!st.ok) {
      r.qdd.max_abs = r.qdd.max_rel = r.force.max_abs = r.force.max_rel = INFINITY;
      r.notes.push_back("femdyn's constrained dynamics: " + st.message);
      continue;
    }
    // q̈ = q̈₀ + Y λ cancels the tree's free acceleration q̈₀ against the loops' part: relative to
    // the larger term (on the N four-bar |q̈₀| is about 100 |q̈|), as h is to the size of its terms.
    accumulate(r.qdd, ws.qdd, s.qdd, std::max(max_abs(s.qdd), max_abs(lws.qdd0)));
    const VecX force = lws.k.J.transpose() * lws.lambda;
    accumulate(r.force, force, s.constraint_force, max_abs(s.constraint_force));
  }
  if (compared < o.states)
    r.notes.push_back("constrained rows at " + std::to_string(compared) + " of " +
                      std::to_string(o.states) + " states: femdyn could not assemble the others (" +
                      why + ")");
  if (compared == 0 && o.states > 0)
    r.failure = "no state of the closed mechanism could be assembled: " + why;
  return r;
}

}  // namespace femdyn::validation
