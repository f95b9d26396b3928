#include "validation/validate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>

#include "compile/compile_level.hpp"
#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/model/model.hpp"
#include "core/spatial/inertia.hpp"
#include "core/spatial/math.hpp"
#include "sim/fixed_step.hpp"
#include "sim/stability.hpp"
#include "validation/twin.hpp"
#include "validation/urdf_twin.hpp"
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
    switch (j.type) {
      case JointType::Revolute:
        tb.joint = TwinBody::Joint::Revolute;
        break;
      case JointType::Prismatic:
        tb.joint = TwinBody::Joint::Prismatic;
        break;
      case JointType::Helical:
        tb.joint = TwinBody::Joint::Helical;
        break;
      case JointType::Universal:
        tb.joint = TwinBody::Joint::Universal;
        break;
      case JointType::Planar:
        tb.joint = TwinBody::Joint::Planar;
        break;
      case JointType::Spherical:
        tb.joint = TwinBody::Joint::Spherical;
        break;
      case JointType::Free:
        tb.joint = TwinBody::Joint::Free;
        break;
      case JointType::Fixed:
        tb.joint = TwinBody::Joint::Fixed;
        break;
    }
    tb.R_pj = j.R_pj;
    tb.p_pj = j.p_pj;
    tb.axis = j.axis;
    tb.axis2 = j.axis2;
    tb.pitch = j.pitch;
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

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The wall time of one call of f: the first call alone when it is slow (over 20 ms), else the
// mean of up to five more (the first warms the buffers up).
template <class F>
double timed(F&& f) {
  auto t0 = Clock::now();
  f();
  const double first = seconds_since(t0);
  if (first > 0.02) return first;
  int calls = 0;
  t0 = Clock::now();
  do {
    f();
    ++calls;
  } while (calls < 5 && seconds_since(t0) < 0.02);
  return seconds_since(t0) / calls;
}

// Cost model constants, measured on a 2-core x86-64 machine (docs/validation.md, "Bounded
// work"); everything else is timed on the model itself.
//   femdyn's M^s beyond kEvaluateProbeLimit coordinates (timed directly below it): per path
//   entry S_kᵀ I^c S_i formed, and per entry of the n x n matrix (mirrored), measured on chains
//   and trees of 3000 and 10,000 bodies; the products M^s V (kMassProducts of them), per entry;
constexpr int kEvaluateProbeLimit = 3000;
constexpr double kSecondsPerPathEntry = 4e-9;
constexpr double kSecondsPerMatrixEntry = 1.5e-9;
constexpr double kSecondsPerProductEntry = 2.5e-9;
//   the Transform route's Tᵀ (M T), per multiply-add;
constexpr double kSecondsPerFlop = 1e-9;
//   Simbody's trajectory, timed over 1/kSimbodyProbeParts of it; its run at 100x the accuracy
//   takes 100^(1/4) = 3.2 times as many steps of its 4th-order method (measured: 3.0 to 3.1);
constexpr double kSimbodyProbeParts = 20;
constexpr double kProbeSeconds = 1;  // the least time the probe of Simbody's run is given
// cond(M^s) is computed (a symmetric eigenproblem a state) up to this n.
constexpr int kConditionLimit = 300;
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// λ_max / λ_min of a symmetric positive definite matrix (infinity where λ_min ≤ 0).
double condition(const MatX& M) {
  if (M.size() == 0) return 1;
  const VecX lambda = Eigen::SelfAdjointEigenSolver<MatX>(M, Eigen::EigenvaluesOnly).eigenvalues();
  return lambda[0] > 0 ? lambda[lambda.size() - 1] / lambda[0]
                       : std::numeric_limits<double>::infinity();
}
const double kTightRatio = std::pow(100.0, 0.25);
//   memory per body of the twin (Simbody's system and state) and of femdyn's workspaces.
constexpr double kBytesPerBody = 20e3;

// q and −q are one rotation: each quaternion of x (a joint state θ, θ̇) takes the sign nearer
// ref's (Simbody keeps the sign it starts with, femdyn's integrators keep w ≥ 0).
void align_quaternions(const Model& m, const VecX& ref, VecX& x) {
  for (const Body& b : m.bodies) {
    const Joint& j = b.joint;
    if (!moves(j) || is_flat(j)) continue;
    const int at = j.idx_q + j.nq - 4;  // the quaternion is last
    if (ref.segment<4>(at).dot(x.segment<4>(at)) < 0) x.segment<4>(at) *= -1;
  }
}

// femdyn's passive motion by RK4 (sim/fixed_step.hpp) at step dt, sampled at `times`
// (multiples of dt): the joint states (θ, θ̇) and the states (q, q̇) at the samples.
// Returns false if the integration failed (M^s singular on the way). An overflow along the
// trajectory (NaN or Inf) is an error, never a skipped comparison.
struct Run {
  std::vector<VecX> x, q, qd;
  std::string failure;  // why the integration failed, if it did
  double wall_time = 0;
};
bool integrate(const Model& m, Workspace& ws, const VecX& q0, const VecX& qd0,
               const std::vector<double>& times, double dt, Run& run,
               const std::function<void(double)>& on_sample) {
  const auto t0 = Clock::now();
  run = Run();
  Rk4 rk4(m, {.dt = dt});
  rk4.reset(0, q0, qd0);
  for (double target : times) {
    const Status st = rk4.advance_to(target);
    if (st.non_finite) throw femdyn::Error("along the trajectory: " + st.message);
    if (!st.ok) {
      run.failure = st.message;
      return false;
    }
    joint_state(m, ws, rk4.q(), rk4.qd());
    VecX x(ws.theta.size() + ws.theta_dot.size());
    x << ws.theta, ws.theta_dot;
    run.x.push_back(std::move(x));
    run.q.push_back(rk4.q());
    run.qd.push_back(rk4.qd());
    if (on_sample) on_sample(target);
  }
  run.wall_time = seconds_since(t0);
  return true;
}

}  // namespace

bool ValidationReport::pass() const {
  if (!failure.empty()) return false;
  for (const QuantityError& q : quantities)
    if (!q.pass()) return false;
  return trajectory.pass();
}

struct Validator::Impl {
  const Model& m;
  ValidationOptions o;
  Clock::time_point start = Clock::now();
  ValidationReport r;  // notes and failures found while building the twin
  TwinModel tm;
  std::unique_ptr<SimbodyTwin> twin;
  Workspace ws;
  MatX V;  // products: the seeded random vectors M^s is multiplied by
  // The frames and the mechanism (up to kKinematicsLimit coordinates), and femdyn's buffers.
  bool kinematics = false, frame_jacobian = false;
  std::vector<TwinFrame> frames;
  FrameKinematics fk;
  MomentumKinematics mk;
  WorkEstimate estimate;
  // Probes (s): femdyn's forward dynamics and its energy at a state.
  double t_fd = 0, t_energy = 0;
  double simbody_cost = 0;  // s: Simbody's two trajectory runs, as estimated

  Impl(const Model& model, ValidationOptions options) : m(model), o(std::move(options)), ws(model) {
    r.model = m.name;
    r.n = m.n();
    r.states = o.states;
    estimate.n = m.n();
    estimate.states = o.states;
    estimate.budget = o.budget;
    estimate.memory_limit = memory_limit(o.memory_limit);
    estimate.dense_mass = r.dense_mass = m.n() <= kDenseMassLimit;
    if (build()) probe();
    estimate.setup = seconds_since(start);
  }

  // The twin, or r.failure saying why there is none.
  bool build() {
    if (m.explicit_table)
      r.notes.push_back(
          "the model gives its correlation table explicitly; DOFs it leaves out or "
          "joins are approximations of the rigid bodies Simbody simulates");
    for (const std::string& a : m.approximations) r.notes.push_back("approximation: " + a);

    // Each body's elements must sum to a rigid body: nothing else can be built in Simbody.
    try {
      tm = twin_model(m);
    } catch (const ModelError& e) {  // a model Simbody cannot hold: no verdict on femdyn
      r.failure = e.what();
      r.not_comparable = true;
      return false;
    }
    if (tm.closed_loop())
      r.notes.push_back("closed loop: " + std::to_string(tm.laws.size()) + " coupled joint(s), " +
                        std::to_string(tm.rods.size()) +
                        " rod(s); Simbody's equations from its constrained forward dynamics");
    bool sums_to_rigid_bodies = true;  // else a failure of the model, not of Simbody
    for (std::size_t b = 0; b < tm.bodies.size(); ++b) {
      const TwinBody& tb = tm.bodies[b];
      const Mat3 I_com = tb.inertia_origin - point_inertia(tb.mass, tb.com);  // parallel axis
      if (tb.mass == 0 && !tb.inertia_origin.isZero(0)) {
        r.failure += (r.failure.empty() ? "" : "; ") +
                     ("body '" + m.bodies[b].name +
                      "' has a rotary inertia but no mass, which a Simbody body cannot have");
        continue;
      }
      if (const auto problem = inertia_problem(I_com, tb.inertia_origin.cwiseAbs().maxCoeff())) {
        sums_to_rigid_bodies = false;
        r.failure += (r.failure.empty() ? "" : "; ") +
                     ("body '" + m.bodies[b].name + "': its elements sum to no rigid body (" +
                      *problem + ")");
      }
    }
    r.not_comparable = !r.failure.empty() && sums_to_rigid_bodies;
    if (!r.failure.empty()) return false;
    try {
      twin = std::make_unique<SimbodyTwin>(tm);
    } catch (const std::exception& e) {
      r.failure = std::string("Simbody refused the twin: ") + e.what();
      return false;
    }
    // The trajectory of a mechanism with loop constraints is the constrained one, in both, from
    // a consistent start (consistent_state).
    twin->close_loops(!m.constraints.empty());
    if (!m.constraints.empty())
      r.notes.push_back(
          "loop constraints: " + std::to_string(m.constraints.size()) + " (" +
          std::to_string(m.constraint_rows) +
          " equations); M, h, Q, qdd, tau and the kinematics compare the spanning tree, the "
          "constrained rows and the trajectory the closed mechanism");
    // (A mechanism without mass has no centre of mass: momentum_kinematics refuses it.)
    double mass = 0;
    for (const TwinBody& b : tm.bodies) mass += b.mass;
    for (const TwinRod& rod : tm.rods) mass += rod.mass;
    kinematics = m.n() <= kKinematicsLimit && mass > 0;
    frame_jacobian = m.n() <= kFrameJacobianLimit;
    for (const Frame& f : m.frames) frames.push_back({f.body, f.R_BF, f.p_BF});
    if (!r.dense_mass) {
      std::mt19937 rng(o.seed + 7919);  // apart from the states' sequence
      V.resize(m.n(), kMassProducts);
      for (int c = 0; c < kMassProducts; ++c) V.col(c) = random_uniform(m.n(), 1, rng);
    }
    return true;
  }

  // femdyn's frames and mechanism at (q, v), stacked as the twin's (TwinKinematics): each
  // frame's pose, velocity J v and acceleration J v̇ + J̇v (with v̇ = `v_dot`, the forward
  // dynamics'), J when compared, and the mechanism in `mk`.
  struct StackedFrames {
    MatX R, p, velocity, acceleration, J;
  } femdyn_frames;
  void femdyn_kinematics(const VecX& q, const VecX& v, const VecX& v_dot) {
    propagate(m, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
    const int nf = static_cast<int>(m.frames.size()), n = m.n();
    StackedFrames& K = femdyn_frames;
    K.R.resize(3, 3 * nf), K.p.resize(3, nf), K.velocity.resize(6, nf);
    K.acceleration.resize(6, nf), K.J.resize(frame_jacobian ? 6 * nf : 0, n);
    for (int f = 0; f < nf; ++f) {
      frame_kinematics(m, ws, f, FrameAxes::LocalWorldAligned, fk);
      K.R.middleCols<3>(3 * f) = fk.R;
      K.p.col(f) = fk.p;
      K.velocity.col(f) = fk.velocity;
      K.acceleration.col(f).noalias() = fk.J * v_dot;
      K.acceleration.col(f) += fk.bias;
      if (frame_jacobian) K.J.middleRows<6>(6 * f) = fk.J;
    }
    momentum_kinematics(m, ws, mk);
  }

  // The compared kinematics (run() adds them after M, h, Q, q̈, τ and the loop).
  struct KinematicErrors {
    QuantityError *pose, *velocity, *acceleration, *jacobian, *com, *com_velocity,
        *com_acceleration, *momentum;
  };

  // femdyn (femdyn_frames, mk at v and v̇) against Simbody's `s`. Positions, velocities and
  // accelerations of the centre of mass and the momentum are measured against the size of what
  // they are made of as well (accumulate's floor; they may vanish by cancellation): the
  // mechanism's extent L = max(‖p_F‖∞, ‖c‖∞) over the frames F, its frames' largest speed V and
  // acceleration A, so P against m V and L_G against m L V. `accelerations` is false where
  // femdyn's forward dynamics failed.
  void compare_kinematics(const TwinKinematics& s, const VecX& v, const VecX& v_dot,
                          bool accelerations, KinematicErrors& e) {
    const StackedFrames& K = femdyn_frames;
    const int nf = static_cast<int>(s.R.size());
    MatX R(3, 3 * nf), p(3, nf);
    for (int f = 0; f < nf; ++f) R.middleCols<3>(3 * f) = s.R[f], p.col(f) = s.p[f];
    const double L = std::max(max_abs(p), max_abs(s.com));
    const double V = max_abs(s.velocity.topRows<3>()), A = max_abs(s.acceleration.topRows<3>());
    accumulate(*e.pose, K.R, R);
    accumulate(*e.pose, K.p, p, L);
    accumulate(*e.velocity, K.velocity, s.velocity);
    if (e.jacobian) accumulate(*e.jacobian, K.J, s.J);
    // The mechanism: m, c (against L), I about c (against m L²).
    accumulate(*e.com, VecX::Constant(1, mk.mass), VecX::Constant(1, s.mass));
    accumulate(*e.com, mk.com, s.com, L);
    accumulate(*e.com, mk.inertia_com, s.inertia_com, s.mass * L * L);
    accumulate(*e.com_velocity, mk.Jcom * v, s.com_velocity, V);  // ċ = J_c v
    const Vec6 h = mk.A * v;                                      // h_G = A_G v
    accumulate(*e.momentum, h.head<3>(), s.momentum.head<3>(), s.mass * V);
    accumulate(*e.momentum, h.tail<3>(), s.momentum.tail<3>(), s.mass * L * V);
    if (!accelerations) {
      e.acceleration->max_abs = e.acceleration->max_rel = INFINITY;
      e.com_acceleration->max_abs = e.com_acceleration->max_rel = INFINITY;
      return;
    }
    accumulate(*e.acceleration, K.acceleration, s.acceleration);
    const Vec3 c_ddot = mk.Jcom * v_dot + mk.com_bias;  // c̈ = J_c v̇ + J̇_c v
    accumulate(*e.com_acceleration, c_ddot, s.com_acceleration, A);
  }

  // The costs, from one state of each kind of work (a state apart from the compared ones).
  void probe() {
    const int n = m.n();
    std::mt19937 rng(o.seed + 104729);
    const VecX q = random_posture(m, rng), qd = random_uniform(n, o.qd_scale, rng),
               tau = random_uniform(n, o.tau_scale, rng), qdd = random_uniform(n, o.qdd_scale, rng);
    t_fd = timed([&] { (void)tree_forward_dynamics(m, ws, q, qd, tau); });
    const double t_id = timed([&] { inverse_dynamics(m, ws, q, qd, qdd); });
    double t_eval = 0;
    if (n <= kEvaluateProbeLimit) {
      t_eval = timed([&] { evaluate(m, ws, q, qd, tau); });
    } else {  // a model of the n x n work, not timed: it would form the matrix to time it
      double path_entries = 0;
      const double per_entry =
          m.identity_coupling ? 1.0
                              : std::pow(m.C.nonZeros() / std::max(1.0, double(m.n_theta())), 2);
      for (const Body& b : m.bodies) {
        if (!moves(b.joint)) continue;
        for (int a = &b - m.bodies.data(); a >= 0; a = m.bodies[a].parent)
          if (moves(m.bodies[a].joint)) path_entries += per_entry;
      }
      t_eval =
          2 * t_id + kSecondsPerPathEntry * path_entries + kSecondsPerMatrixEntry * double(n) * n;
      if (m.mass_route == MassRoute::Transform) t_eval += kSecondsPerFlop * 2.0 * m.n_u() * n * n;
    }
    t_energy =
        m.mass_route == MassRoute::Composite ? timed([&] { (void)energy(m, ws, q, qd); }) : t_eval;
    double t_sim = 0;
    try {
      t_sim = timed([&] { (void)twin->equations(q, qd, tau, r.dense_mass ? nullptr : &V); }) +
              timed([&] { (void)twin->inverse_dynamics(q, qd, qdd); });
    } catch (const std::exception&) {
      // A state Simbody cannot take is reported by the comparison itself; the estimate goes on.
    }
    double t_kinematics = 0;  // both engines' frames and momentum
    if (kinematics) {
      t_kinematics = timed([&] { femdyn_kinematics(q, qd, qdd); });
      try {
        t_kinematics += timed([&] { (void)twin->kinematics(q, qd, tau, frames, frame_jacobian); });
      } catch (const std::exception&) {
        // As above: the comparison reports it.
      }
    }
    estimate.per_state = t_fd + t_eval + t_id + t_sim + t_kinematics;
    if (!r.dense_mass) estimate.per_state += kSecondsPerProductEntry * double(n) * n;  // M^s V
    estimate.pointwise = o.states * estimate.per_state;

    // The trajectory as usually refined: femdyn's RK4 at dt, dt/2 and dt/4 (7 S0 steps of 4
    // evaluations, S0 = t_end / dt, within max_rk4_steps a run), the energy at each sample, and
    // Simbody's two runs, timed on the trajectory's first twentieth from its first state (Simbody's
    // error control sets its step by the motion at hand, which that stretch shows) and scaled to
    // the whole (its steps at 100x the accuracy: 100^(1/4) = 3.2 times as many).
    if (o.t_end > 0 && o.states > 0) {
      const double s0 = std::max(1.0, std::round(o.t_end / o.rk4_step));
      const double samples = std::max(1, o.samples) + 1;
      const double steps = 3 * s0 + (2 * s0 <= o.max_rk4_steps ? 4 * s0 : 0);
      estimate.trajectory = steps * 4 * t_fd + samples * t_energy;
      if (twin->can_simulate()) {
        std::mt19937 first(o.seed);  // the first state of run(): the trajectory's start
        VecX q0 = random_posture(m, first), qd0 = random_uniform(n, o.qd_scale, first);
        std::string why;
        if (!m.constraints.empty()) (void)consistent_state(m, q0, qd0, why);
        const double stretch = o.t_end / kSimbodyProbeParts;
        const double scale = (1 + kTightRatio) * kSimbodyProbeParts;
        // The probe gets its share of the budget, and at least kProbeSeconds whatever the budget:
        // a small budget would otherwise cut it short and the estimate would be the budget
        // echoed back ("at least 5.1 s" for --budget 5, then 6.0 for 6, …). A probe that runs
        // out of even that is a lower bound, said so.
        TwinRunLimits limits;
        limits.wall_time = std::max(o.budget / scale, kProbeSeconds);
        const TwinRun probe =
            twin->simulate(q0, qd0, {0.0, stretch}, o.simbody_accuracy,
                           SimbodyIntegrator::RungeKuttaMerson, TwinSampling::StepToEach, limits);
        simbody_cost = scale * probe.stats.wall_time;
        estimate.at_least = probe.stats.out_of_time;
        estimate.trajectory += simbody_cost;
      }
    }

    // Memory: femdyn's n x n M^s, what its routes form besides, Simbody's matrices, the
    // samples, and a measured amount per body.
    const double nt = m.n_theta(), nb = static_cast<double>(m.bodies.size());
    double bytes = dense_bytes(n, n) + kBytesPerBody * nb;
    if (m.mass_route == MassRoute::Transform)
      bytes += 2 * dense_bytes(m.n_u(), n) + 2 * dense_bytes(3 * nb, n);  // T, M T, Jω, Jv
    if (m.dynamics_route == DynamicsRoute::Cholesky && m.mass_pattern.solver == SolverKind::Dense)
      bytes += dense_bytes(n, n);                                                 // its factor
    if (m.coupling_level) bytes += 2 * dense_bytes(nt, nt) + dense_bytes(nt, n);  // the tree's
    if (tm.closed_loop())
      bytes += 5 * dense_bytes(n, n);  // q̈'s response, its inverse, M^s, h's and Q's products
    else if (r.dense_mass || !m.identity_coupling)  // a coupled tree forms M to solve for q̈
      bytes +=
          2 * dense_bytes(nt, nt) + 3 * dense_bytes(n, n);  // calcM, M_θ, Cᵀ M_θ C, a difference
    else
      bytes += 4 * dense_bytes(n, kMassProducts);
    if (o.t_end > 0) bytes += 8 * dense_bytes(std::max(1, o.samples) + 1, 2 * (nt + n));
    if (kinematics && m.mass_route != MassRoute::Transform)
      bytes += 2 * dense_bytes(3 * nb, n);  // Jω, Jv
    if (frame_jacobian) bytes += 2 * dense_bytes(6 * static_cast<double>(frames.size()), n);
    estimate.bytes = bytes;
  }

  // The trajectory from (q0, q̇0), within what is left of the budget at `deadline`.
  TrajectoryReport trajectory(const VecX& q0, const VecX& qd0, Clock::time_point deadline,
                              const std::function<void(double)>& progress) {
    TrajectoryReport tr;
    tr.t_end = o.t_end;
    tr.constrained = !m.constraints.empty();
    if (o.t_end <= 0) {
      tr.skipped = "--t-end 0";
      return tr;
    }
    if (!twin->can_simulate(&tr.skipped)) return tr;
    if (tr.constrained) {  // a consistent start: Φ = 0, Φ_q q̇ = 0
      VecX q = q0, qd = qd0;
      std::string why;
      if (!consistent_state(m, q, qd, why)) {
        tr.skipped =
            "femdyn cannot assemble a start (the first state or the neutral posture): " + why;
        return tr;
      }
      return trajectory_from(q, qd, deadline, progress, tr);
    }
    return trajectory_from(q0, qd0, deadline, progress, tr);
  }

  TrajectoryReport trajectory_from(const VecX& q0, const VecX& qd0, Clock::time_point deadline,
                                   const std::function<void(double)>& progress,
                                   TrajectoryReport tr) {
    const auto left = [&] {
      return std::chrono::duration<double>(deadline - Clock::now()).count();
    };
    const int samples = std::max(1, o.samples);
    // femdyn's RK4 at dt and dt/2; sample times lie on the grid.
    std::vector<double> times;
    // The first step, within half of RK4's linear stability limit at the start (a stiff spring
    // or damper would blow up a run at rk4_step: a diagnosis femdyn check makes the same way).
    double first = o.rk4_step;
    if (const Linearization lin = linearize(m, ws, q0, qd0, VecX::Zero(m.n())); lin.status.ok)
      if (const auto stable = largest_stable_step(lin, IntegratorKind::Rk4))
        first = std::min(first, 0.5 * *stable);
    double dt = o.t_end / std::max(1.0, std::round(o.t_end / first));
    for (int i = 0; i <= samples; ++i) times.push_back(dt * std::round(o.t_end * i / samples / dt));
    const std::string singular = "femdyn's integration failed along the trajectory";
    Run coarse, fine;
    double done = 0;  // estimated seconds of trajectory work done, for the progress line
    const auto femdyn_run = [&](double step, Run& run) {
      const double cost = std::round(o.t_end / step) * 4 * t_fd;
      const double before = done;
      const bool ok = integrate(m, ws, q0, qd0, times, step, run,
                                [&](double t) { progress(before + cost * t / o.t_end); });
      done = before + cost;
      return ok;
    };
    if (!femdyn_run(dt, coarse) || !femdyn_run(dt / 2, fine)) {
      tr.skipped = singular + (": " + (coarse.failure.empty() ? fine.failure : coarse.failure));
      return tr;
    }
    double estimate_rk4 = 0, scale = 1;
    const auto rk4_estimate = [&] {
      estimate_rk4 = 0, scale = 1;
      for (std::size_t i = 0; i < times.size(); ++i) {
        estimate_rk4 = std::max(estimate_rk4, max_abs(coarse.x[i] - fine.x[i]) / 15);
        scale = std::max(scale, max_abs(fine.x[i]));
      }
    };
    rk4_estimate();

    // Simbody at its accuracy and 100x tighter (the difference estimates its own error), each
    // bounded by what is left; the tighter run takes about 100^(1/4) = 3.2 times as long.
    const double tight_ratio = kTightRatio;
    std::vector<TwinSample> sim, tight;
    {
      TwinRunLimits limits;
      limits.wall_time = std::max(1e-3, left() / (1 + tight_ratio));
      double before = done;
      const double cost = simbody_cost / (1 + tight_ratio);  // the run at its accuracy
      limits.on_sample = [&](double t) { progress(before + cost * t / o.t_end); };
      TwinRun a =
          twin->simulate(q0, qd0, times, o.simbody_accuracy, SimbodyIntegrator::RungeKuttaMerson,
                         TwinSampling::StepToEach, limits);
      if (!a.stats.ok) {
        tr.stopped =
            "Simbody at accuracy " + format_short(o.simbody_accuracy) + ": " + a.stats.failure;
        return tr;
      }
      if (tight_ratio * a.stats.wall_time > 2 * left()) {
        tr.stopped = "Simbody at accuracy " + format_short(o.simbody_accuracy / 100) +
                     " would take about " + format_duration(tight_ratio * a.stats.wall_time) +
                     " (" + format_duration(a.stats.wall_time) + " at " +
                     format_short(o.simbody_accuracy) + "), more than the " +
                     format_duration(std::max(0.0, left())) + " left of the budget";
        return tr;
      }
      limits.wall_time = std::max(1e-3, left());
      before = done += cost;
      limits.on_sample = [&](double t) { progress(before + tight_ratio * cost * t / o.t_end); };
      TwinRun b =
          twin->simulate(q0, qd0, times, o.simbody_accuracy / 100,
                         SimbodyIntegrator::RungeKuttaMerson, TwinSampling::StepToEach, limits);
      if (!b.stats.ok) {
        tr.stopped = "Simbody at accuracy " + format_short(o.simbody_accuracy / 100) + ": " +
                     b.stats.failure;
        return tr;
      }
      done += tight_ratio * cost;
      sim = std::move(a.samples);
      tight = std::move(b.samples);
    }
    double simbody_estimate = 0, tight_scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      VecX xs(fine.x[i].size()), xt(fine.x[i].size());
      xs << sim[i].theta, sim[i].theta_dot;
      xt << tight[i].theta, tight[i].theta_dot;
      align_quaternions(m, fine.x[i], xs);
      align_quaternions(m, fine.x[i], xt);
      simbody_estimate = std::max(simbody_estimate, max_abs(xs - xt));
      tight_scale = std::max(tight_scale, max_abs(xt));
    }

    // Halve femdyn's step until its own error estimate (dt against dt/2) is below the target,
    // within max_rk4_steps steps a run and the budget; not at all when Simbody's own estimate
    // already leaves the comparison unresolved.
    tr.rk4_step = dt / 2;
    if (10 * simbody_estimate + 1e-12 * tight_scale > o.resolved_tolerance * tight_scale) {
      if (estimate_rk4 > o.rk4_target * scale)
        tr.refinement =
            "not halved further: Simbody's own error estimate alone leaves the comparison "
            "unresolved";
    } else {
      while (estimate_rk4 > o.rk4_target * scale) {
        if (o.t_end / dt * 2 > o.max_rk4_steps) {
          tr.refinement = "not halved beyond dt = " + format_short(dt / 2) + " s: the limit of " +
                          format_short(o.max_rk4_steps) + " steps a run";
          break;
        }
        const double next = 2 * fine.wall_time;  // the run at dt/4 against the one at dt/2
        if (next > left()) {
          tr.refinement = "not halved beyond dt = " + format_short(dt / 2) +
                          " s: the run at dt = " + format_short(dt / 4) + " s would take about " +
                          format_duration(next) + ", more than the " +
                          format_duration(std::max(0.0, left())) + " left of the budget (--budget)";
          break;
        }
        dt /= 2;
        std::swap(coarse, fine);
        if (!femdyn_run(dt / 2, fine)) {
          tr.skipped = singular + (": " + fine.failure);
          return tr;
        }
        tr.rk4_step = dt / 2;
        rk4_estimate();
      }
    }

    tr.run = true;
    tr.rk4_error_estimate = 0;
    scale = 1;
    for (std::size_t i = 0; i < times.size(); ++i) {
      VecX xs(fine.x[i].size()), xt(fine.x[i].size());
      xs << sim[i].theta, sim[i].theta_dot;
      xt << tight[i].theta, tight[i].theta_dot;
      align_quaternions(m, fine.x[i], xs);
      align_quaternions(m, fine.x[i], xt);
      const double err = max_abs(fine.x[i] - xt);  // the finer runs of both
      const double e = energy(m, ws, fine.q[i], fine.qd[i]).total();
      tr.t.push_back(times[i]);
      tr.error.push_back(err);
      tr.energy_femdyn.push_back(e);
      tr.energy_simbody.push_back(tight[i].energy);
      tr.max_state_error = std::max(tr.max_state_error, err);
      // RK4 is 4th order: x_dt − x_exact ≈ 16/15 (x_dt − x_dt/2); the finer run is 16x better.
      tr.rk4_error_estimate =
          std::max(tr.rk4_error_estimate, max_abs(coarse.x[i] - fine.x[i]) / 15);
      tr.simbody_error_estimate = std::max(tr.simbody_error_estimate, max_abs(xs - xt));
      tr.energy_change_femdyn =
          std::max(tr.energy_change_femdyn, std::abs(e - tr.energy_femdyn[0]));
      tr.energy_change_simbody =
          std::max(tr.energy_change_simbody, std::abs(tight[i].energy - tight[0].energy));
      scale = std::max(scale, max_abs(xt));
    }
    // The two runs may differ by what each integrator gets wrong (with a margin of 10), plus
    // round-off. A comparison whose integrators are not that accurate proves nothing: the motion
    // is unresolved (chaotic over this time, or too fast) and fails with that reason.
    // A closed mechanism's runs are projected onto the constraints, Simbody's to its accuracy
    // (setConstraintTolerance) and femdyn's after every step to 1e-12 (assemble's tolerance):
    // errors of that size, not of the step, that neither estimate sees: the floor is Simbody's
    // accuracy instead of round-off.
    const double floor = tr.constrained ? std::max(1e-12, o.simbody_accuracy) : 1e-12;
    tr.tolerance = 10 * (tr.rk4_error_estimate + tr.simbody_error_estimate) + floor * scale;
    tr.resolved = tr.tolerance <= o.resolved_tolerance * scale;
    return tr;
  }

  ValidationReport run() {
    r.estimate = estimate;
    if (!r.failure.empty()) {
      r.wall_time = seconds_since(start);
      return r;
    }
    const auto run_start = Clock::now();
    const auto deadline = run_start + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(o.budget));
    double total = estimate.seconds();
    const auto progress = [&](double done) {
      if (!o.progress) return;
      total = std::max(total, done);
      o.progress(done, total);
    };
    SimbodyTwin& tw = *twin;
    const double tol = o.tolerance > 0 ? o.tolerance : pointwise_tolerance(m);
    for (const char* name : {"M", "h", "Q", "qdd", "tau"})
      r.quantities.push_back({name, 0, 0, tol});
    if (tm.closed_loop()) r.quantities.push_back({"loop", 0, 0, tol});
    const std::size_t first_kinematic = r.quantities.size();
    if (kinematics)
      for (const char* name : {"frame pose", "frame velocity", "frame acceleration", "frame J",
                               "com", "com velocity", "com acceleration", "momentum"})
        if (frame_jacobian || std::string(name) != "frame J")
          r.quantities.push_back({name, 0, 0, tol});
    KinematicErrors ek{};
    if (kinematics) {
      QuantityError* at = &r.quantities[first_kinematic];
      ek.pose = at++, ek.velocity = at++, ek.acceleration = at++;
      ek.jacobian = frame_jacobian ? at++ : nullptr;
      ek.com = at++, ek.com_velocity = at++, ek.com_acceleration = at++, ek.momentum = at++;
    } else if (m.n() > kKinematicsLimit) {
      r.notes.push_back("frames, centre of mass and momentum not compared beyond " +
                        std::to_string(kKinematicsLimit) + " coordinates");
    } else {
      r.notes.push_back(
          "frames, centre of mass and momentum not compared: the mechanism has no mass");
    }
    QuantityError &eM = r.quantities[0], &eh = r.quantities[1], &eQ = r.quantities[2],
                  &eqdd = r.quantities[3], &etau = r.quantities[4];
    // The loop's closure at femdyn's θ = g(q), θ̇ = G q̇: Simbody's constraint errors relative
    // to the longest rod (m) and its speed, or in rad and rad/s for couplers alone.
    double length = 1;
    if (!tm.rods.empty()) {
      length = 0;
      for (const TwinRod& rod : tm.rods) length = std::max(length, rod.length);
    }

    std::mt19937 rng(o.seed);
    VecX q0, qd0;
    double cond = 1;  // the largest cond(M^s) over the states (n ≤ kConditionLimit)
    for (int k = 0; k < o.states; ++k) {
      const VecX q = random_posture(m, rng);
      const VecX qd = random_uniform(m.n(), o.qd_scale, rng);
      const VecX tau = random_uniform(m.n(), o.tau_scale, rng);
      const VecX qdd = random_uniform(m.n(), o.qdd_scale, rng);
      if (k == 0) q0 = q, qd0 = qd;

      const TwinEquations s = tw.equations(q, qd, tau, r.dense_mass ? nullptr : &V);
      if (tm.closed_loop()) {
        QuantityError& loop = r.quantities[5];
        const double speed = length * std::max(1.0, max_abs(qd));
        loop.max_abs = std::max({loop.max_abs, s.loop_position_error, s.loop_velocity_error});
        loop.max_rel =
            std::max({loop.max_rel, s.loop_position_error / length, s.loop_velocity_error / speed});
      }
      const Status st = tree_forward_dynamics(m, ws, q, qd, tau);
      evaluate(m, ws, q, qd, tau);
      if (r.dense_mass)
        accumulate(eM, ws.Ms, s.M);
      else
        accumulate(eM, ws.Ms * V, s.MV);
      accumulate(eh, ws.h, s.h, bias_floor(ws.Ms, qd));
      accumulate(eQ, ws.Q, s.Q);
      if (m.n() <= kConditionLimit && o.tolerance <= 0) cond = std::max(cond, condition(ws.Ms));
      if (st.ok) {
        accumulate(eqdd, ws.qdd, s.qdd);
      } else {
        eqdd.max_abs = eqdd.max_rel = INFINITY;
        r.notes.push_back("femdyn: " + st.message);
      }
      if (kinematics) {
        const VecX v_dot = st.ok ? ws.qdd : VecX::Zero(m.n());
        femdyn_kinematics(q, qd, v_dot);
        compare_kinematics(tw.kinematics(q, qd, tau, frames, frame_jacobian), qd, v_dot, st.ok, ek);
      }
      inverse_dynamics(m, ws, q, qd, qdd);
      accumulate(etau, ws.tau, tw.inverse_dynamics(q, qd, qdd));
      progress((k + 1) * estimate.per_state);
    }
    // q̈ = (M^s)⁻¹ (Q − h) by two backward-stable solvers differs by up to about ε cond(M^s)
    // relative (a relative change ε of M^s moves q̈ by up to that), exact as both are: its
    // tolerance is at least 10 ε cond. M^s, h and Q themselves keep the fixed one, so a modelling
    // error still fails there.
    if (const double by_cond = 10 * kEpsilon * cond;
        std::isfinite(by_cond) && by_cond > eqdd.tolerance) {
      eqdd.tolerance = by_cond;
      r.notes.push_back("q̈'s tolerance is 10 ε cond(M^s) = " + format_number(by_cond, "%.3g") +
                        ", cond(M^s) up to " + format_number(cond, "%.3g") +
                        " at the compared states");
    }
    if (!m.constraints.empty()) {  // the closed mechanism at its own consistent states
      LoopRows loops = compare_loops(m, tw, o, tol);
      for (QuantityError* e : {&loops.qdd, &loops.force, &loops.closure})
        r.quantities.push_back(*e);
      for (std::string& note : loops.notes) r.notes.push_back(std::move(note));
      if (!loops.failure.empty()) r.failure = loops.failure;
    }
    if (!r.dense_mass)
      r.notes.push_back("M^s compared by its products with " + std::to_string(kMassProducts) +
                        " seeded random vectors (n > " + std::to_string(kDenseMassLimit) +
                        "): the error is ‖ΔM^s V‖∞ / ‖M^s V‖∞");
    if (o.states > 0) {
      const double pointwise = estimate.pointwise;
      r.trajectory =
          trajectory(q0, qd0, deadline, [&](double done) { progress(pointwise + done); });
    }
    r.wall_time = seconds_since(start);
    return r;
  }
};

// ‖x_femdyn − x_simbody‖∞ / max(‖x_simbody‖∞, floor) (the absolute error when both are 0). The
// floor is the size of what the quantity is made of, where it may vanish by cancellation (a
// centre of mass at the origin): the error is then measured against its parts.
void accumulate(QuantityError& e, const MatX& femdyn, const MatX& simbody, double floor) {
  const double d = max_abs(femdyn - simbody);
  const double scale = std::max(max_abs(simbody), floor);
  e.max_abs = std::max(e.max_abs, d);
  e.max_rel = std::max(e.max_rel, scale > 0 ? d / scale : d);
}

// The size of the parts h is summed from, h_a = Σ_bc D_abc q̇_b q̇_c with D of the size of M^s
// per unit displacement: ‖M^s‖∞ ‖q̇‖∞². h of a mechanism whose bodies turn about their own
// principal axes cancels to ~1e-20 (PyBullet's minitaur), where a relative error means nothing.
double bias_floor(const MatX& Ms, const VecX& qd) {
  const double v = qd.size() ? qd.cwiseAbs().maxCoeff() : 0.0;
  return max_abs(Ms) * v * v;
}

double pointwise_tolerance(const Model& m) {
  std::vector<int> depth(m.bodies.size(), 1);  // bodies on the path from the world
  int d = 0;
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    if (const int p = m.bodies[b].parent; p >= 0) depth[b] = depth[p] + 1;  // parents first
    d = std::max(d, depth[b]);
  }
  const double eps = std::numeric_limits<double>::epsilon();
  return std::max(1e-10, eps * d * d);
}

Validator::Validator(const Model& model, ValidationOptions options)
    : impl_(std::make_unique<Impl>(model, std::move(options))) {}
Validator::~Validator() = default;

const WorkEstimate& Validator::estimate() const { return impl_->estimate; }

std::string Validator::refusal(const std::string& label) const {
  const WorkEstimate& e = impl_->estimate;
  if (!impl_->r.failure.empty() || e.within()) return {};
  const ValidationOptions& o = impl_->o;
  const bool time = e.seconds() > e.budget, memory = e.bytes > e.memory_limit;
  std::string text = label + ": validating n = " + std::to_string(e.n) +
                     " coordinates would take " + (e.at_least ? "at least " : "about ") +
                     format_duration(e.seconds()) + " (" + std::to_string(e.states) +
                     " states of " + format_duration(e.per_state) +
                     (o.t_end > 0 ? ", the trajectory " + format_duration(e.trajectory) : "") +
                     ") and " + format_bytes(e.bytes) + " of memory, beyond ";
  if (time) text += "the budget of " + format_number(e.budget, "%.4g") + " s";
  if (time && memory) text += " and ";
  if (memory)
    text += "the memory limit of " + format_bytes(e.memory_limit) +
            (o.memory_limit > 0 ? "" : " (half the available memory)");
  text += ": use ";
  // How to proceed: no trajectory, fewer states, a larger budget, a larger memory limit.
  std::vector<std::string> ways;
  if (time) {
    const double P = e.pointwise, T = e.trajectory, B = e.budget, s = e.per_state;
    const auto states = [&](double seconds) {
      return std::to_string(std::max(1, static_cast<int>(seconds / s)));
    };
    if (T > 0 && P <= B)
      ways.push_back("--t-end 0 (t_end=0: no trajectory, about " + format_duration(P) + ")");
    // A shorter trajectory: its cost is about proportional to its length (unknown beyond a
    // lower bound when Simbody's probe ran out of time).
    if (const double t_end = T > 0 ? 0.8 * o.t_end * (B - P) / T : 0;
        P < B && t_end >= 1e-3 && !e.at_least)
      ways.push_back("--t-end " + format_number(t_end, "%.2g") + " (t_end=)");
    if (P + T > B && T + s <= B) ways.push_back("--states " + states(B - T) + " (states=)");
    if (T > 0 && P > B && s <= B) ways.push_back("--t-end 0 --states " + states(B));
    ways.push_back("--budget " + format_number(std::ceil(1.1 * e.seconds()), "%.0f") +
                   (e.at_least ? " or more" : "") + " (budget=)");
  }
  if (memory)
    ways.push_back(max_memory_option(e.bytes) + " (max_memory=, GB) if that much memory is free");
  for (std::size_t i = 0; i < ways.size(); ++i)
    text += (i == 0 ? "" : i + 1 == ways.size() ? ", or " : ", ") + ways[i];
  return text;
}

ValidationReport Validator::run() { return impl_->run(); }

void Validator::set_progress(std::function<void(double, double)> progress) {
  impl_->o.progress = std::move(progress);
}

ValidationReport validate(const Model& m, const ValidationOptions& o) {
  Validator v(m, o);
  if (std::string why = v.refusal(m.where.empty() ? m.name : m.where); !why.empty())
    throw OverBudget(why);
  return v.run();
}

QuantityError validate_urdf_import(const Model& m, const std::string& path,
                                   const ValidationOptions& o, std::string& failure,
                                   bool balance_inertia) {
  QuantityError e{"import", 0, 0, o.tolerance > 0 ? o.tolerance : pointwise_tolerance(m)};
  // --floating-base puts the root link first, on a free joint to the world named after it
  // (io/urdf_loader.cpp); the twin then floats the root of the XML's tree.
  const bool floating = !m.bodies.empty() && m.bodies[0].parent < 0 &&
                        m.bodies[0].joint.type == JointType::Free &&
                        m.bodies[0].joint.name == m.bodies[0].name;
  std::unique_ptr<UrdfTwin> twin;
  try {
    twin = std::make_unique<UrdfTwin>(path, m.gravity, floating, balance_inertia);
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
    const UrdfTwinEquations s = twin->equations(m.coordinate_names, m.configuration_names, q, qd);
    accumulate(e, ws.Ms, s.M);
    accumulate(e, ws.h, s.h, bias_floor(ws.Ms, qd));
    accumulate(e, ws.Q, s.Q);
  }
  return e;
}

}  // namespace femdyn::validation
