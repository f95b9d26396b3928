// The validator's pointwise comparison: at random states, femdyn's M^s, h, Q, q̈ and τ, a closed
// loop's closure, and the frames, centre of mass and momentum against the Simbody twin's
// (docs/validation.md).
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "validation/urdf_twin.hpp"
#include "validation/validate_loops.hpp"
#include "validation/validator.hpp"

namespace femdyn::validation {
namespace {

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

// The loop's closure is measured relative to the longest rod (m) and its speed, or in rad and
// rad/s for couplers alone.
double loop_length(const TwinModel& tm) {
  if (tm.rods.empty()) return 1;
  double length = 0;
  for (const TwinRod& rod : tm.rods) length = std::max(length, rod.length);
  return length;
}

}  // namespace

void Validator::Impl::femdyn_kinematics(const VecX& q, const VecX& v, const VecX& v_dot) {
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

// femdyn (femdyn_frames, mk at v and v̇) against Simbody's `s`. Positions, velocities and
// accelerations of the centre of mass and the momentum are measured against the size of what
// they are made of as well (accumulate's floor; they may vanish by cancellation): the
// mechanism's extent L = max(‖p_F‖∞, ‖c‖∞) over the frames F, its frames' largest speed V and
// acceleration A, so P against m V and L_G against m L V. `accelerations` is false where
// femdyn's forward dynamics failed.
void Validator::Impl::compare_kinematics(const TwinKinematics& s, const VecX& v, const VecX& v_dot,
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

Validator::Impl::KinematicErrors Validator::Impl::add_kinematic_quantities(double tol) {
  KinematicErrors ek{};
  if (!kinematics) {
    r.notes.push_back(m.n() > kKinematicsLimit
                          ? "frames, centre of mass and momentum not compared beyond " +
                                std::to_string(kKinematicsLimit) + " coordinates"
                          : std::string("frames, centre of mass and momentum not compared: the "
                                        "mechanism has no mass"));
    return ek;
  }
  const std::size_t first = r.quantities.size();
  for (const char* name : {"frame pose", "frame velocity", "frame acceleration", "frame J", "com",
                           "com velocity", "com acceleration", "momentum"})
    if (frame_jacobian || std::string(name) != "frame J") r.quantities.push_back({name, 0, 0, tol});
  QuantityError* at = &r.quantities[first];
  ek.pose = at++, ek.velocity = at++, ek.acceleration = at++;
  ek.jacobian = frame_jacobian ? at++ : nullptr;
  ek.com = at++, ek.com_velocity = at++, ek.com_acceleration = at++, ek.momentum = at++;
  return ek;
}

void Validator::Impl::compare_state(const VecX& q, const VecX& qd, const VecX& tau, const VecX& qdd,
                                    KinematicErrors& ek, double& cond) {
  QuantityError &eM = r.quantities[0], &eh = r.quantities[1], &eQ = r.quantities[2],
                &eqdd = r.quantities[3], &etau = r.quantities[4];
  const TwinEquations s = twin->equations(q, qd, tau, r.dense_mass ? nullptr : &V);
  if (tm.closed_loop()) {  // the loop's closure at femdyn's θ = g(q), θ̇ = G q̇
    QuantityError& loop = r.quantities[5];
    const double length = loop_length(tm), speed = length * std::max(1.0, max_abs(qd));
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
    compare_kinematics(twin->kinematics(q, qd, tau, frames, frame_jacobian), qd, v_dot, st.ok, ek);
  }
  inverse_dynamics(m, ws, q, qd, qdd);
  accumulate(etau, ws.tau, twin->inverse_dynamics(q, qd, qdd));
}

// q̈ = (M^s)⁻¹ (Q − h) by two backward-stable solvers differs by up to about ε cond(M^s)
// relative (a relative change ε of M^s moves q̈ by up to that), exact as both are: its
// tolerance is at least 10 ε cond. M^s, h and Q themselves keep the fixed one, so a modelling
// error still fails there.
void Validator::Impl::tolerate_conditioning(double cond) {
  QuantityError& eqdd = r.quantities[3];
  if (const double by_cond = 10 * kEpsilon * cond;
      std::isfinite(by_cond) && by_cond > eqdd.tolerance) {
    eqdd.tolerance = by_cond;
    r.notes.push_back("q̈'s tolerance is 10 ε cond(M^s) = " + format_number(by_cond, "%.3g") +
                      ", cond(M^s) up to " + format_number(cond, "%.3g") +
                      " at the compared states");
  }
}

ValidationReport Validator::Impl::run() {
  r.estimate = estimate;
  if (!r.failure.empty()) {
    r.wall_time = seconds_since(start);
    return r;
  }
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(o.budget));
  double total = estimate.seconds();
  const auto progress = [&](double done) {
    if (!o.progress) return;
    total = std::max(total, done);
    o.progress(done, total);
  };
  const double tol = o.tolerance > 0 ? o.tolerance : pointwise_tolerance(m);
  for (const char* name : {"M", "h", "Q", "qdd", "tau"}) r.quantities.push_back({name, 0, 0, tol});
  if (tm.closed_loop()) r.quantities.push_back({"loop", 0, 0, tol});
  KinematicErrors ek = add_kinematic_quantities(tol);

  std::mt19937 rng(o.seed);
  VecX q0, qd0;
  double cond = 1;  // the largest cond(M^s) over the states (n ≤ kConditionLimit)
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng);
    const VecX qd = random_rates(m, o.qd_scale, rng);
    const VecX tau = random_uniform(m.n(), o.tau_scale, rng);
    const VecX qdd = random_uniform(m.n(), o.qdd_scale, rng);
    if (k == 0) q0 = q, qd0 = qd;
    compare_state(q, qd, tau, qdd, ek, cond);
    progress((k + 1) * estimate.per_state);
  }
  tolerate_conditioning(cond);
  if (!m.constraints.empty()) {  // the closed mechanism at its own consistent states
    LoopRows loops = compare_loops(m, *twin, o, tol);
    for (QuantityError* e : {&loops.qdd, &loops.force, &loops.closure}) r.quantities.push_back(*e);
    for (std::string& note : loops.notes) r.notes.push_back(std::move(note));
    if (!loops.failure.empty()) r.failure = loops.failure;
  }
  if (!r.dense_mass)
    r.notes.push_back("M^s compared by its products with " + std::to_string(kMassProducts) +
                      " seeded random vectors (n > " + std::to_string(kDenseMassLimit) +
                      "): the error is ‖ΔM^s V‖∞ / ‖M^s V‖∞");
  if (o.states > 0) {
    const double pointwise = estimate.pointwise;
    r.trajectory = trajectory(q0, qd0, deadline, [&](double done) { progress(pointwise + done); });
  }
  r.wall_time = seconds_since(start);
  return r;
}

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
    const VecX qd = random_rates(m, o.qd_scale, rng);
    evaluate(m, ws, q, qd, VecX());
    const UrdfTwinEquations s = twin->equations(m.coordinate_names, m.configuration_names, q, qd);
    accumulate(e, ws.Ms, s.M);
    accumulate(e, ws.h, s.h, bias_floor(ws.Ms, qd));
    accumulate(e, ws.Q, s.Q);
  }
  return e;
}

}  // namespace femdyn::validation
