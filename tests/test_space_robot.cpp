// The space robot of the paper's title (models/space_robot.json): a satellite on a free joint,
// a 7-DOF arm and the dexterous hand, in zero gravity. In free float the joint torques are
// internal forces, so the linear momentum and the angular momentum about the centre of mass are
// conserved, and with zero momentum the centre of mass does not move while the arm moves the
// satellite (docs/space_robot.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "tests/momentum.hpp"
#ifdef FEMDYN_WITH_SIMBODY
#include "tests/validation_checks.hpp"
#endif

using namespace femdyn;
using namespace femdyn::test;

namespace {

Model space_robot() { return load_model(model_path("space_robot.json")); }

// The same robot with its finger joints held about their rest angles as a servo would hold
// them: a spring and a damper on each (k = 1e-4 N m/rad, c = 1e-5 N m s/rad; about critical for
// a fingertip of 2e-7 kg m²). Springs and dampers on joints are internal forces: they change no
// momentum, and the Simbody comparison below checks them on joints after the quaternion.
Model held_space_robot() {
  return load_text(R"({"model": "space_robot", "params": {"hand": {"finger":
                       {"stiffness": 1e-4, "damping": 1e-5}}}})");
}

// The robot whose fingers' distal joints follow their middle ones: linearly (θ_dip = 0.8 θ_pip)
// or through hand_fourbar.json's four-bar with its coupler rod.
Model coupled_space_robot() {
  return load_text(R"({"model": "space_robot", "params": {"hand": {"finger":
                       {"coupling": {"ratio": 0.8}}}}})");
}
// (Without the coupler rod the law alone: tests/momentum.hpp sums body momenta, and a rod
// spanning two bodies is not a body.)
Model fourbar_space_robot(bool coupler_rod = true) {
  return load_text(std::string(R"({"model": "space_robot", "params": {"hand": {"finger": {
    "coupling": {"four_bar": {"ground": 0.03, "input": 0.005, "coupler": 0.0285, "output": 0.007,
                 "branch": 1, "input_offset": 2.0264, "input_sign": -1})") +
                   (coupler_rod ? R"(, "coupler_mass": 0.0005)" : "") + "}}}}}");
}

// Smooth joint torques on the arm and the fingers, none on the satellite's six rates (they would
// be external forces): τ_i(t) = a_i sin(ω_i t + φ_i), a_i = M^s_ii (0.5 … 1.5 rad/s²) at the
// reference posture, so that every joint, from the shoulder to a fingertip, moves about as fast.
Actuation joint_torques(const Model& m, unsigned seed) {
  Workspace ws(m);
  mass_matrix(m, ws, reference_posture(m));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  VecX a = VecX::Zero(m.n()), w = VecX::Zero(m.n()), phi = VecX::Zero(m.n());
  for (int i = 6; i < m.n(); ++i) {
    a[i] = ws.Ms(i, i) * (0.5 + u(rng));
    w[i] = 0.5 + 2 * u(rng);
    phi[i] = 6 * u(rng);
  }
  return
      [a, w, phi](double t, VecX& tau) { tau = a.array() * (w.array() * t + phi.array()).sin(); };
}

// v for the arm's rates `arm` and the satellite's rates that cancel their momentum: the momentum
// h = A v (about the world origin) is linear in v, so v_base = −A_base⁻¹ A_arm v_arm.
VecX zero_momentum_rates(const Model& m, Workspace& ws, const VecX& q, const VecX& arm) {
  MatX A(6, m.n());
  for (int j = 0; j < m.n(); ++j) A.col(j) = momentum(m, ws, q, VecX::Unit(m.n(), j));
  VecX v = arm;
  v.head<6>() = -A.leftCols<6>().partialPivLu().solve(A.rightCols(m.n() - 6) * arm.tail(m.n() - 6));
  return v;
}

std::unique_ptr<Integrator> dopri(const Model& m, Actuation tau) {
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-11;
  o.adaptive.atol = 1e-12;
  return make_integrator(m, o, std::move(tau));
}

}  // namespace

TEST_CASE("the space robot is a free-floating satellite with a 7-DOF arm and a 20-DOF hand") {
  const Model m = space_robot();
  CHECK(m.n() == 6 + 7 + 20);
  CHECK(m.n_q() == m.n() + 1);
  CHECK(m.gravity.isZero(0));
  CHECK(m.configuration_names.front() == "satellite.x");
  CHECK(m.configuration_names[3] == "satellite.qw");
  CHECK(m.coordinate_names[5] == "satellite.wz");
  CHECK(m.coordinate_names[6] == "joint1");
  CHECK(m.coordinate_names.back() == "thumb_dip");
  double mass = 0;
  for (const RigidInertia& L : m.body_inertia) mass += L.m;
  CHECK(mass > 200 + 17.5);  // the satellite and the arm's seven links, plus the hand
  CHECK(mass < 200 + 17.5 + 1);
}

// The largest relative drift of the momentum about the COM over `seconds` under joint torques,
// from a random state with both momenta above 1 SI, and dopri's steps.
struct Drift {
  double angular = 0, linear = 0;
  long steps = 0;
};
Drift momentum_drift(const Model& m, double seconds) {
  Workspace ws(m);
  std::mt19937 rng(17);
  const VecX q0 = random_posture(m, rng), v0 = random_uniform(m.n(), 0.5, rng);
  const Vec6 h0 = momentum_about_com(m, ws, q0, v0);
  REQUIRE(h0.head<3>().norm() > 1);
  REQUIRE(h0.tail<3>().norm() > 1);
  auto integrator = dopri(m, joint_torques(m, 3));
  integrator->reset(0, q0, v0);
  double worst_L = 0, worst_p = 0;
  for (int k = 1; k <= 20; ++k) {
    REQUIRE(integrator->advance_to(seconds * k / 20).ok);
    const Vec6 h = momentum_about_com(m, ws, integrator->q(), integrator->qd());
    worst_L = std::max(worst_L, (h - h0).head<3>().norm() / h0.head<3>().norm());
    worst_p = std::max(worst_p, (h - h0).tail<3>().norm() / h0.tail<3>().norm());
  }
  return {worst_L, worst_p, integrator->stats().steps};
}

// [long]: not run under the sanitizers (docs/robustness.md#sanitizers).
TEST_CASE("in free float dopri conserves the space robot's momentum about its centre of mass",
          "[long]") {
  const Drift d = momentum_drift(held_space_robot(), 10.0);
  INFO("relative drift over 10 s: angular " << d.angular << ", linear " << d.linear << " in "
                                            << d.steps << " steps");
  CHECK(d.angular <= 1e-9);
  CHECK(d.linear <= 1e-9);
}

TEST_CASE("with coupled or four-bar fingers the floating robot still conserves its momentum") {
  for (const Model& m : {coupled_space_robot(), fourbar_space_robot(false)}) {
    REQUIRE(m.n() == 6 + 7 + 15);  // each finger and the thumb: 3 coordinates
    REQUIRE(m.n_q() == m.n() + 1);
    const Drift d = momentum_drift(m, 2.0);
    INFO(m.name << (m.coupling_level ? " (four-bar)" : " (linear)") << ": angular " << d.angular
                << ", linear " << d.linear);
    CHECK(d.angular <= 1e-9);
    CHECK(d.linear <= 1e-9);
  }
}

// [long]: not run under the sanitizers (docs/robustness.md#sanitizers).
TEST_CASE(
    "with zero momentum the space robot's arm turns and moves the satellite, and the centre of "
    "mass stays",
    "[long]") {
  const Model m = held_space_robot();
  Workspace ws(m);
  std::mt19937 rng(23);
  const VecX q0 = reference_posture(m);
  VecX arm = VecX::Zero(m.n());
  arm.segment(6, 7) = random_uniform(7, 0.3, rng);
  const VecX v0 = zero_momentum_rates(m, ws, q0, arm);
  REQUIRE(momentum(m, ws, q0, v0).norm() < 1e-12);
  const Vec3 c0 = centre_of_mass(m, ws);
  propagate(m, ws, q0, v0, {.jacobian = false, .bias = false, .rows = false});
  const Vec3 p0 = ws.origin + ws.body[0].p;
  const Mat3 R0 = ws.body[0].R;

  auto integrator = dopri(m, joint_torques(m, 5));
  integrator->reset(0, q0, v0);
  double drift = 0;
  for (int k = 1; k <= 20; ++k) {
    REQUIRE(integrator->advance_to(0.5 * k).ok);
    momentum(m, ws, integrator->q(), integrator->qd());
    drift = std::max(drift, (centre_of_mass(m, ws) - c0).norm());
  }
  // The satellite has turned and its centre has moved, by amounts of the arm's mass ratio.
  const BodyState& sat = ws.body[0];
  const double turned = Eigen::AngleAxisd(R0.transpose() * sat.R).angle();
  const double moved = (ws.origin + sat.p - p0).norm();
  INFO("centre of mass drift " << drift << " m; satellite turned " << turned << " rad, moved "
                               << moved << " m in " << integrator->stats().steps << " steps");
  CHECK(turned > 0.01);
  CHECK(moved > 0.001);
  CHECK(drift < 1e-9);
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("the space robot's M^s, h, q̈ and τ and a trajectory match Simbody, held or not",
          "[validation]") {
  require_pass(validation::validate(space_robot(), quick(4, 0.1)), "space robot");
  // Springs and dampers on joints whose q and v addresses differ (after the quaternion).
  require_pass(validation::validate(held_space_robot(), quick(4, 0.1)), "held space robot");
  // Couplings after the quaternion: θ = C_q q + θ0_q, and the four-bar's law and rods.
  require_pass(validation::validate(coupled_space_robot(), quick(4, 0.1)), "coupled fingers");
  require_pass(validation::validate(fourbar_space_robot(), quick(4, 0.1)), "four-bar fingers");
}
#endif
