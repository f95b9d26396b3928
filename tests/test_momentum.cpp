// The mechanism as a whole (core/kinematics/momentum.hpp): centre of mass, its Jacobian, the
// centroidal momentum matrix A_G and their biases, against finite differences of the poses, against
// the body-level sums of tests/momentum.hpp (independent code: the condensed body inertias), and
// against Newton and Euler: the momentum changes only by the external wrench, so
// A_G q̈ + Ȧ_G v = (m g, 0) with q̈ from forward dynamics. The generalized Jacobian against a
// free-floating simulation, whose momentum the dynamics alone conserves.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/kinematics/sampling.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "tests/momentum.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A floating tree of every element form: a rigid body on a free joint, a space bar, a lumped
// point with a rotary node, and a rod from the base to the arm, its ends on the arm's joint
// axis (so the kinematics keeps its length) and spanning two bodies. Gravity along −z.
const char* kFloating = R"({"name": "floating", "gravity": [0, 0, -9.81], "bodies": [
  {"name": "base", "parent": "world", "joint": {"type": "free"}, "nodes": {"top": [0.2, 0, 0.15]},
   "elements": [{"type": "rigid_body", "mass": 3, "com": [0.1, 0.02, 0],
                 "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015, "ixy": 0.001}},
                {"type": "rod", "nodes": ["top", "arm/low"], "mass": 0.2}]},
  {"name": "arm", "parent": "base", "joint": {"type": "revolute", "axis": [0, 0, 1],
     "origin": {"xyz": [0.2, 0, 0]}, "spring": {"stiffness": 2, "rest": 0.3}, "damping": 0.1},
   "nodes": {"root": [0, 0, 0], "tip": [0.3, 0, 0], "low": [0, 0, -0.05]},
   "elements": [{"type": "space_bar", "nodes": ["root", "tip"], "density": 2700, "area": 3e-4,
                 "Iy": 2.25e-9, "Iz": 2.5e-8}]},
  {"name": "wrist", "parent": "arm", "joint": {"type": "spherical", "origin": {"xyz": [0.3, 0, 0]}},
   "nodes": {"c": [0.05, 0.01, 0.02]},
   "elements": [{"type": "lumped_point", "node": "c", "mass": 0.4},
                {"type": "rotary_node", "node": "c",
                 "inertia": [[2e-4, 1e-5, 0], [1e-5, 3e-4, 2e-5], [0, 2e-5, 4e-4]]}]},
  {"name": "slider", "parent": "wrist", "joint": {"type": "prismatic", "axis": [1, 0, 0],
     "origin": {"xyz": [0.1, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.3, "com": [0.05, 0, 0.01],
                 "inertia": {"ixx": 0.001, "iyy": 0.002, "izz": 0.002}}]}]})";

// The centre of mass at q ⊕ ±h e, and the momentum matrix's product A v there.
void check_against_differences(const Model& m, unsigned seed) {
  Workspace ws(m);
  std::mt19937 rng(seed);
  const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
  const VecX zero = VecX::Zero(m.n());
  const double h = 1e-6;
  MomentumKinematics k, a, b;
  momentum_kinematics(m, ws, q, v, k);
  // J_c's columns: ċ along each rate.
  for (int c = 0; c < m.n(); ++c) {
    const VecX e = VecX::Unit(m.n(), c);
    momentum_kinematics(m, ws, integrate_posture(m, q, h * e), zero, a);
    momentum_kinematics(m, ws, integrate_posture(m, q, -h * e), zero, b);
    const Vec3 fd = (a.com - b.com) / (2 * h);
    CHECK((k.Jcom.col(c) - fd).norm() < 1e-7 * (1 + fd.norm()));
  }
  CHECK((k.com_velocity - k.Jcom * v).norm() < 1e-12 * (1 + k.com_velocity.norm()));
  CHECK((k.momentum - k.A * v).norm() < 1e-12 * (1 + k.momentum.norm()));
  CHECK((k.momentum.head<3>() - k.mass * k.com_velocity).norm() < 1e-12 * k.momentum.norm());
  // Ȧ_G v = d/dt (A_G v) and J̇_c v along q ⊕ t v; the centroidal moment about the moving c
  // is what the bias is the rate of (ċ × P = 0).
  momentum_kinematics(m, ws, integrate_posture(m, q, h * v), v, a);
  momentum_kinematics(m, ws, integrate_posture(m, q, -h * v), v, b);
  const Vec6 fd = (a.A * v - b.A * v) / (2 * h);
  CHECK((k.bias - fd).norm() < 1e-6 * (1 + fd.norm()));
  const Vec3 fd_c = (a.Jcom * v - b.Jcom * v) / (2 * h);
  CHECK((k.com_bias - fd_c).norm() < 1e-6 * (1 + fd_c.norm()));
  // The locked inertia about c is symmetric positive definite.
  CHECK((k.inertia_com - k.inertia_com.transpose()).norm() < 1e-12 * k.inertia_com.norm());
  CHECK(Eigen::SelfAdjointEigenSolver<Mat3>(k.inertia_com).eigenvalues().minCoeff() > 0);
}

// Σ of the elements' masses, independently of M.
double element_mass(const Model& m) {
  double total = 0;
  for (const ElementEntry& e : m.elements) total += e.element->mass_properties().mass;
  return total;
}

// ḣ_G from forward dynamics under random joint torques (none on the free base's rates) against
// the external wrench about c: gravity, (m g, 0).
void check_external_wrench(const Model& m) {
  Workspace ws(m);
  std::mt19937 rng(31);
  const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
  VecX tau = random_uniform(m.n(), 1.0, rng);
  tau.head<6>().setZero();
  REQUIRE(forward_dynamics(m, ws, q, v, tau).ok);
  const VecX qdd = ws.qdd;
  MomentumKinematics k;
  momentum_kinematics(m, ws, q, v, k);
  Vec6 wrench;
  wrench << k.mass * m.gravity, Vec3::Zero();
  const Vec6 rate = k.A * qdd + k.bias;
  CHECK((rate - wrench).norm() < 1e-9 * (k.A.norm() * qdd.norm() + k.bias.norm() + 1));
}

}  // namespace

TEST_CASE("centre of mass, J_c, A_G and their biases equal finite differences", "[momentum]") {
  SECTION("a floating tree of every element form, a spanning rod among them") {
    const Model m = load_text(kFloating);
    REQUIRE(!m.condensable);
    check_against_differences(m, 11);
  }
  SECTION("the four-bar finger: a coupling law and its coupler rod") {
    const Model m = load_model(model_path("finger_fourbar.json"));
    REQUIRE(m.coupling_level);
    check_against_differences(m, 12);
  }
  SECTION("the hand") { check_against_differences(load_model(model_path("hand.json")), 13); }
}

TEST_CASE("mass, centre of mass and momentum equal the sums over the body inertias", "[momentum]") {
  // The spatial double pendulum's first hinge leaves its link's rx rate out of u (it stays 0),
  // while the link's full inertia tensor couples it: its momentum I ω still has that component.
  for (const char* name :
       {"hand.json", "branched_tree.json", "space_robot.json", "spatial_double_pendulum.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    REQUIRE(m.condensable);
    Workspace ws(m);
    std::mt19937 rng(21);
    const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
    MomentumKinematics k;
    momentum_kinematics(m, ws, q, v, k);
    CHECK(k.mass == Approx(element_mass(m)).epsilon(1e-12));
    const Vec6 body_sum = momentum_about_com(m, ws, q, v);  // (angular, linear)
    CHECK((k.com - centre_of_mass(m, ws)).norm() < 1e-12 * (1 + k.com.norm()));
    CHECK((k.momentum.head<3>() - body_sum.tail<3>()).norm() < 1e-11 * (1 + body_sum.norm()));
    CHECK((k.momentum.tail<3>() - body_sum.head<3>()).norm() < 1e-11 * (1 + body_sum.norm()));
  }
  SECTION("a rod's mass sits half at each end") {
    const Model m = load_text(kFloating);
    MomentumKinematics k;
    Workspace ws(m);
    momentum_kinematics(m, ws, neutral_posture(m), VecX::Zero(m.n()), k);
    CHECK(k.mass == Approx(element_mass(m)).epsilon(1e-12));
  }
}

TEST_CASE("the momentum changes by the external wrench alone: A_G q̈ + Ȧ_G v = (m g, 0)",
          "[momentum]") {
  // Joint torques, springs, dampers and the rod's forces are internal; gravity acts at c.
  SECTION("a floating tree with a rod, under gravity") {
    check_external_wrench(load_text(kFloating));
  }
  SECTION("the space robot, four-bar fingers with coupler rods") {
    check_external_wrench(load_text(R"({"model": "space_robot", "params": {"hand": {"finger":
      {"coupling": {"four_bar": {"ground": 0.03, "input": 0.005, "coupler": 0.0285,
       "output": 0.007, "branch": 1, "input_offset": 2.0264, "input_sign": -1},
       "coupler_mass": 0.0005}}}}})"));
  }
}

TEST_CASE("the generalized Jacobian gives the tip's velocity in free float", "[momentum]") {
  // The dynamics conserves the momentum by itself; J* predicts the tip from the arm's rates.
  const Model m = load_model(model_path("space_robot.json"));
  REQUIRE(m.gravity.isZero());
  const int tip = find_frame(m, "index_tip");
  REQUIRE(tip >= 0);
  REQUIRE(floating_base_rate(m) == 0);
  for (const bool drifting : {false, true}) {
    INFO((drifting ? "with momentum" : "from rest"));
    std::mt19937 rng(41);
    VecX v0 = VecX::Zero(m.n());
    if (drifting) v0.head<6>() = random_uniform(6, 0.05, rng);
    // Each joint accelerated at about 1 rad/s² (τ_i ~ M^s_ii), none pushed from outside.
    Workspace ws0(m);
    mass_matrix(m, ws0, neutral_posture(m));
    VecX tau = ws0.Ms.diagonal().cwiseProduct(random_uniform(m.n(), 1.0, rng));
    tau.head<6>().setZero();
    IntegratorOptions o;
    o.kind = IntegratorKind::Rk4;
    o.fixed.dt = 1e-4;
    auto integ = make_integrator(m, o, [tau](double, VecX& out) { out = tau; });
    integ->reset(0, neutral_posture(m), v0);
    REQUIRE(integ->advance_to(0.05).ok);
    const VecX q = integ->q(), v = integ->qd();
    Workspace ws(m);
    propagate(m, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
    FrameKinematics f;
    MomentumKinematics k;
    GeneralizedJacobian g;
    frame_kinematics(m, ws, tip, FrameAxes::LocalWorldAligned, f);
    momentum_kinematics(m, ws, k);
    generalized_jacobian(m, f, k, g);
    REQUIRE(g.rates.size() == static_cast<std::size_t>(m.n() - 6));
    VecX v_m(m.n() - 6);
    for (int j = 0; j < m.n() - 6; ++j) v_m[j] = v[g.rates[j]];
    const Vec6 predicted = g.J * v_m + g.drift;
    CHECK((predicted - f.velocity).norm() < 1e-8 * f.velocity.norm());
    CHECK(f.velocity.norm() > 1e-3);  // the tip moves
    CAPTURE(g.drift.norm(), f.velocity.norm());
    CHECK((g.drift.norm() < 1e-6 * f.velocity.norm()) == !drifting);
  }
}

TEST_CASE("the generalized Jacobian asks for one tree on a free joint", "[momentum]") {
  const Model fixed = load_model(model_path("hand.json"));
  CHECK_THROWS_WITH(floating_base_rate(fixed),
                    Catch::Contains("needs one tree on a free joint at its root"));
}

TEST_CASE("kinematics prints the centroidal quantities, and J* on a floating tree",
          "[momentum][cli]") {
  const Model m = load_model(model_path("space_robot.json"));
  const Run floating =
      run("kinematics " + model_path("space_robot.json") + " --frame index_tip --json");
  REQUIRE(floating.code == 0);
  const auto j = nlohmann::json::parse(floating.out);
  CHECK(j["centroidal"]["mass"].get<double>() == Approx(element_mass(m)).epsilon(1e-12));
  CHECK(j["centroidal"]["A"].size() == 6);
  CHECK(j["centroidal"]["A"][0].size() == static_cast<std::size_t>(m.n()));
  const auto& g = j["frames"][0]["generalized_jacobian"];
  CHECK(g["rates"][0] == "joint1");
  CHECK(g["J"].size() == 6);
  CHECK(g["J"][0].size() == static_cast<std::size_t>(m.n() - 6));
  const Run fixed = run("kinematics " + model_path("hand.json") + " --json");
  REQUIRE(fixed.code == 0);
  const auto h = nlohmann::json::parse(fixed.out);
  CHECK(h["centroidal"]["com"].size() == 3);
  CHECK(!h["frames"][0].contains("generalized_jacobian"));
}
