// The model's loop constraints and springs in the Simbody twin (twin_constraints.hpp), and
// Simbody's constrained forward dynamics with them (SimbodyTwin::loop_dynamics). Compiled like
// twin.cpp (C++17, without NDEBUG).
#include "validation/twin_constraints.hpp"

#include <algorithm>
#include <memory>
#include <utility>

#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "validation/simtk_convert.hpp"
#include "validation/twin_impl.hpp"

namespace femdyn::validation {

namespace constraints {

namespace {

SimTK::MobilizedBody& body(SimTK::SimbodyMatterSubsystem& matter,
                           std::vector<SimTK::MobilizedBody>& tree, int b) {
  return b < 0 ? static_cast<SimTK::MobilizedBody&>(matter.updGround()) : tree[b];
}

SimTK::Constraint add(SimTK::SimbodyMatterSubsystem& matter, const TwinConstraint& c,
                      std::vector<SimTK::MobilizedBody>& tree) {
  using namespace SimTK;
  MobilizedBody& A = body(matter, tree, c.body_a);
  MobilizedBody& B = body(matter, tree, c.body_b);
  switch (c.type) {
    case TwinConstraint::Type::Ball:
      return Constraint::Ball(A, to_simtk(c.p_a), B, to_simtk(c.p_b));
    case TwinConstraint::Type::PointOnLine:
      return Constraint::PointOnLine(B, UnitVec3(to_simtk(c.direction)), to_simtk(c.p_b), A,
                                     to_simtk(c.p_a));
    case TwinConstraint::Type::PointInPlane:
      return Constraint::PointInPlane(B, UnitVec3(to_simtk(c.direction)),
                                      c.direction.normalized().dot(c.p_b), A, to_simtk(c.p_a));
    case TwinConstraint::Type::Weld:
      return Constraint::Weld(A, Transform(to_simtk(c.R_a), to_simtk(c.p_a)), B,
                              Transform(to_simtk(c.R_b), to_simtk(c.p_b)));
    case TwinConstraint::Type::Rod:
      return Constraint::Rod(A, to_simtk(c.p_a), B, to_simtk(c.p_b), c.length);
    case TwinConstraint::Type::Gear: {
      // f(θ_0, θ_1, …) = θ_0 − Σ r_i θ_i − offset = 0
      std::vector<MobilizedBodyIndex> bodies;
      for (int b : c.bodies) bodies.push_back(tree.at(b).getMobilizedBodyIndex());
      const std::vector<MobilizerQIndex> which(bodies.size(), MobilizerQIndex(0));
      Vector a(static_cast<int>(c.ratios.size()) + 2);
      a[0] = 1;
      for (std::size_t i = 0; i < c.ratios.size(); ++i) a[1 + static_cast<int>(i)] = -c.ratios[i];
      a[a.size() - 1] = -c.offset;
      auto f = std::make_unique<Function::Linear>(a);
      return Constraint::CoordinateCoupler(matter, f.release(), bodies, which);  // owns f
    }
  }
  throw femdyn::Error("unknown constraint type");
}

}  // namespace

void add_springs(SimTK::GeneralForceSubsystem& forces, SimTK::SimbodyMatterSubsystem& matter,
                 const TwinModel& m, std::vector<SimTK::MobilizedBody>& tree) {
  using namespace SimTK;
  for (const TwinSpring& s : m.springs) {
    const MobilizedBody& A = body(matter, tree, s.body_a);
    const MobilizedBody& B = body(matter, tree, s.body_b);
    if (s.stiffness != 0)
      Force::TwoPointLinearSpring(forces, A, to_simtk(s.p_a), B, to_simtk(s.p_b), s.stiffness,
                                  s.rest_length);
    if (s.damping != 0)
      Force::TwoPointLinearDamper(forces, A, to_simtk(s.p_a), B, to_simtk(s.p_b), s.damping);
  }
}

std::vector<SimTK::Constraint> add_constraints(SimTK::SimbodyMatterSubsystem& matter,
                                               const TwinModel& m,
                                               std::vector<SimTK::MobilizedBody>& tree) {
  std::vector<SimTK::Constraint> out;
  for (const TwinConstraint& c : m.constraints) {
    try {
      out.push_back(add(matter, c, tree));
    } catch (const std::exception& e) {
      throw femdyn::Error("Simbody refuses constraint '" + escaped(c.name) +
                          "': " + one_line(e.what()));
    }
    out.back().setDisabledByDefault(true);
  }
  return out;
}

}  // namespace constraints

void SimbodyTwin::Impl::enable_loops(bool on) {
  for (const SimTK::Constraint& c : loop_constraints) {
    if (c.isDisabled(state) != on) continue;
    if (on)
      c.enable(state);
    else
      c.disable(state);
  }
  loops_enabled = on;
}

void SimbodyTwin::close_loops(bool closed) { impl_->simulate_closed = closed; }

namespace {

// The twin poses the loop constraints on a tree whose coordinates each drive a joint directly.
void require_loops_posable(const TwinModel& model, bool couplers) {
  if (model.closed_loop())
    throw femdyn::Error(
        "the Simbody twin closes loop constraints on a tree only, not with nonlinear "
        "couplings or rods");
  if (!couplers)
    throw femdyn::Error(
        "the Simbody twin closes loop constraints only where each coordinate drives a "
        "joint directly");
}

// Exchanges two states for a scope (SimTK::State moves are pointer moves): the entry points
// work on Impl::state, and this puts another state there and back, also on an exception.
class SwappedState {
 public:
  SwappedState(SimTK::State& a, SimTK::State& b) : a_(a), b_(b) { std::swap(a_, b_); }
  ~SwappedState() { std::swap(a_, b_); }
  SwappedState(const SwappedState&) = delete;
  SwappedState& operator=(const SwappedState&) = delete;

 private:
  SimTK::State& a_;
  SimTK::State& b_;
};

}  // namespace

void SimbodyTwin::Impl::prepare_loop_timing() {
  require_loops_posable(model, couplers);
  bench_loop_state = state;  // the tree's variables, loops disabled, no τ
  for (const SimTK::Constraint& c : loop_constraints) c.enable(bench_loop_state);
  bench_tau = SimTK::Vector(state.getNU(), 0.0);
  bench_loops_ready = true;
}

void SimbodyTwin::time_constrained(const VecX& q, const VecX& qd, const VecX& tau) {
  Impl& s = *impl_;
  if (!s.bench_loops_ready) s.prepare_loop_timing();
  const SwappedState loops(s.state, s.bench_loop_state);
  // τ_k on the joint q_k drives directly, as time_forward (the rotation P of a ball's or free
  // joint's triple left out: the same work, not the same numbers; loop_dynamics has them).
  for (int k = 0; k < s.model.n(); ++k)
    if (s.independent[k] >= 0) s.bench_tau[s.theta_u[s.independent[k]]] = tau[k];
  s.tau_forces.setAllMobilityForces(s.state, s.bench_tau);
  s.set_state(q, qd, SimTK::Stage::Acceleration, kTiming);
}

TwinLoopDynamics SimbodyTwin::loop_dynamics(const VecX& q, const VecX& qd, const VecX& tau) {
  using namespace SimTK;
  Impl& s = *impl_;
  require_loops_posable(s.model, s.couplers);
  TwinLoopDynamics out;
  try {
    s.enable_loops(true);
    s.set_state(q, qd, Stage::Velocity);
    const auto max_abs = [](const SimTK::Vector& x) {
      double m = 0;
      for (int i = 0; i < x.size(); ++i) m = std::max(m, std::abs(x[i]));
      return m;
    };
    out.position_error = max_abs(s.state.getQErr());
    out.velocity_error = max_abs(s.state.getUErr());
    s.tau_forces.setAllMobilityForces(s.state, s.independent_forces(tau));
    s.system.realize(s.state, Stage::Acceleration);
    // v̇ = Pᵀ (u̇ − Ṗ v); q̈_k the rate of the joint coordinate k drives.
    const VecX theta_ddot = s.gather(s.state.getUDot() - s.pdot_v, s.rot);
    out.qdd.resize(s.model.n());
    for (int k = 0; k < s.model.n(); ++k) out.qdd[k] = theta_ddot[s.independent[k]];
    // M u̇ + Gᵀ λ = f: the constraints apply −Gᵀ λ; on q, −Cᵀ Pᵀ Gᵀ λ (the couplers' part,
    // orthogonal to the coupled motion, drops out).
    SimTK::Vector GT_lambda;
    s.matter.multiplyByGTranspose(s.state, s.state.getMultipliers(), GT_lambda);
    out.constraint_force = -s.reduce(GT_lambda);
    s.tau_forces.clearAllMobilityForces(s.state);
    s.enable_loops(false);
  } catch (const std::exception& e) {
    s.tau_forces.clearAllMobilityForces(s.state);
    s.enable_loops(false);
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
  return out;
}

}  // namespace femdyn::validation
