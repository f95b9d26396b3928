// Actuators, friction and limits (docs/control.md): the rotor's reflected inertia I_a G² in M^s
// on every route, τ, q̈ and the kinetic energy; regularised Coulomb friction; effort saturation
// with its counts; velocity-limit reports; enforced stops. Against closed forms (a spring arm's
// period with the rotor, a Coulomb block's deceleration, a stop's bounce), finite differences
// (dE/dt = P_nc), and one-line errors for bad input.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "core/kinematics/momentum.hpp"
#include "io/params.hpp"
#include "models/builder.hpp"
#include "models/random_tree.hpp"
#include "sim/integrator.hpp"
#include "sim/motion.hpp"
#include "sim/recorded_run.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;

namespace {

// A seeded random tree (revolute and prismatic joints) as a JSON document, every joint given a
// rotor (armature in [0.01, 0.1], a gear ratio of either sign), and with `couplings` j3 following
// j1 and j0 linearly.
Json tree_with_rotors(unsigned seed, int bodies, bool couplings) {
  const Json params = {{"seed", seed}, {"bodies", bodies}, {"branching", 0.4}, {"prismatic", true}};
  Json doc = random_tree(Params(params, "random_tree: "));
  doc["gravity"] = {0.1, -0.2, -9.81};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.01, 0.1), g(1, 30);
  for (Json& b : doc["bodies"]) {
    b["joint"]["armature"] = u(rng);
    b["joint"]["gear"] = (rng() % 2 ? 1 : -1) * g(rng);
  }
  if (couplings)
    doc["couplings"] = Json::parse(R"([{"joint": "j3", "follows": [{"joint": "j1", "ratio": 0.7},
                                        {"joint": "j0", "ratio": -0.4}], "offset": 0.2}])");
  return doc;
}

Json without_rotors(Json doc) {
  for (Json& b : doc["bodies"]) {
    b["joint"].erase("armature");
    b["joint"].erase("gear");
  }
  return doc;
}

// diag(I_a G²) over θ̇.
VecX reflected(const Model& m) {
  VecX a(m.n_theta());
  for (int j = 0; j < m.n_theta(); ++j) a[j] = m.bodies[m.theta_joint[j]].joint.reflected_inertia;
  return a;
}

// G = ∂θ̇/∂q̇ at q, column by column (joint_state: θ̇ = C q̇ or G q̇ through a law).
MatX rate_map(const Model& m, const VecX& q) {
  Workspace ws(m);
  MatX G(m.n_theta(), m.n());
  for (int a = 0; a < m.n(); ++a) {
    joint_state(m, ws, q, VecX::Unit(m.n(), a));
    G.col(a) = ws.theta_dot;
  }
  return G;
}

// With rotors `a` and without `b` at random states: M^s_a − M^s_b = Gᵀ diag(I_a G²) G, M^s q̈ + h
// = Q on `a`'s forward dynamics, τ back from its inverse dynamics, and the kinetic energy
// ½ q̇ᵀ M^s q̇ (which holds ½ Σ I_a G² θ̇²).
void check_rotors(const Model& a, const Model& b, unsigned seed) {
  Workspace wa(a), wb(b);
  std::mt19937 rng(seed);
  const VecX D = reflected(a);
  REQUIRE(D.minCoeff() > 0);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng),
               tau = random_uniform(a.n(), 3, rng);
    const MatX G = rate_map(a, q);
    evaluate(a, wa, q, qd, tau);
    evaluate(b, wb, q, qd, tau);
    const MatX rotors = G.transpose() * D.asDiagonal() * G;
    CHECK(rel_error(wa.Ms - wb.Ms, rotors) < 1e-9);
    const MatX Ms = wa.Ms;
    const VecX h = wa.h, Q = wa.Q;
    mass_matrix(a, wa, q);
    CHECK(rel_error(wa.Ms, Ms) < 1e-12);
    REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
    CHECK(rel_error(Ms * wa.qdd + h, Q) < 1e-9);
    const VecX qdd = wa.qdd;
    inverse_dynamics(a, wa, q, qd, qdd);
    CHECK(rel_error(wa.tau, tau, Ms.cwiseAbs().maxCoeff() * qdd.cwiseAbs().maxCoeff()) < 1e-9);
    const Energy E = energy(a, wa, q, qd), Eb = energy(b, wb, q, qd);
    CHECK(E.kinetic == Approx(0.5 * qd.dot(Ms * qd)).epsilon(1e-10));
    const VecX theta_dot = G * qd;
    CHECK(E.kinetic - Eb.kinetic ==
          Approx(0.5 * theta_dot.dot(D.asDiagonal() * theta_dot)).epsilon(1e-8));
  }
}

// The model of `doc` on a route choice.
Model on_route(const Json& doc, const RouteChoice& r) {
  return load_text(doc.dump(), {.routes = r});
}

// A 1 kg point on a prismatic joint along x, no gravity, with `joint` fields added.
Json block(const Json& joint) {
  Json j = {{"name", "x"}, {"type", "prismatic"}, {"axis", {1, 0, 0}}};
  j.update(joint);
  return {{"name", "block"},
          {"gravity", {0, 0, 0}},
          {"bodies",
           {{{"name", "cart"},
             {"parent", "world"},
             {"joint", j},
             {"elements", {{{"type", "lumped_point"}, {"node", {0, 0, 0}}, {"mass", 1.0}}}}}}}};
}

// The spring arm of tests/helpers (1 kg·m² about the joint) with `joint` fields added.
Json arm(double k, const Json& joint, double g = 0) {
  Json doc = Json::parse(arm_json(k, 0, g));
  doc["bodies"][0]["joint"].update(joint);
  return doc;
}

// (q, q̇) of a run at t_end by dopri at tight tolerances.
struct End {
  double t, q, qd, balance;
  long evaluations, saturated_evaluations;
};
End run_to(const Model& m, double q0, double qd0, double t_end, Actuation tau = {}) {
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-11;
  o.adaptive.atol = 1e-13;
  auto integ = make_integrator(m, o, std::move(tau));
  integ->reset(0, VecX::Constant(1, q0), VecX::Constant(1, qd0));
  REQUIRE(integ->advance_to(t_end).ok);
  const Energy E = integ->motion().energy_at(integ->y().data());
  const Energy E0 = integ->divergence().initial();
  return {integ->t(),
          integ->q()[0],
          integ->qd()[0],
          E.total() - E0.total() - integ->work(),
          integ->motion().evaluations(),
          integ->motion().saturated_evaluations()};
}

}  // namespace

TEST_CASE("armature: every route adds Gᵀ diag(I_a G²) G to M^s, and to τ, q̈ and the energy",
          "[actuators]") {
  for (unsigned seed = 1; seed <= 3; ++seed) {
    INFO("seed " << seed);
    const Json doc = tree_with_rotors(seed, 9, false), plain = without_rotors(doc);
    const RouteChoice routes[] = {{},  // compile's choice: the articulated-body recursion
                                  {.mass = MassRoute::Transform,
                                   .force = ForceRoute::Nodes,
                                   .dynamics = DynamicsRoute::Cholesky},
                                  {.mass = MassRoute::Composite,
                                   .force = ForceRoute::Bodies,
                                   .dynamics = DynamicsRoute::Cholesky},
                                  {.mass = MassRoute::Composite,
                                   .force = ForceRoute::Nodes,
                                   .dynamics = DynamicsRoute::Cholesky},
                                  {.mass = MassRoute::Transform,
                                   .force = ForceRoute::Bodies,
                                   .dynamics = DynamicsRoute::Cholesky}};
    for (const RouteChoice& r : routes) {
      const Model a = on_route(doc, r), b = on_route(plain, r);
      INFO("mass route " << static_cast<int>(a.mass_route) << ", force route "
                         << static_cast<int>(a.force_route) << ", dynamics route "
                         << static_cast<int>(a.dynamics_route));
      CHECK(a.has_armature);
      CHECK(!b.has_armature);
      check_rotors(a, b, seed);
    }
  }
  // Couplings θ = C q + θ0: Cᵀ diag(I_a G²) C, on both mass routes.
  for (unsigned seed = 4; seed <= 5; ++seed) {
    const Json doc = tree_with_rotors(seed, 8, true), plain = without_rotors(doc);
    for (const MassRoute mr : {MassRoute::Composite, MassRoute::Transform}) {
      const Model a = on_route(doc, {.mass = mr}), b = on_route(plain, {.mass = mr});
      REQUIRE(!a.identity_coupling);
      check_rotors(a, b, seed);
    }
  }
  // A nonlinear coupling level θ = g(q): Gᵀ diag(I_a G²) G with G = ∂g/∂q at q.
  Json doc = Json::parse(nonlinear_coupled_tree_json(3));
  for (Json& body : doc["bodies"]) body["joint"]["armature"] = 0.05, body["joint"]["gear"] = 4;
  const Model a = load_text(doc.dump()), b = load_text(without_rotors(doc).dump());
  REQUIRE(a.coupling_level);
  check_rotors(a, b, 3);
}

// tree_with_rotors with every third joint made spherical, its rotor I_a on each of its three
// rates (no gear: a ball's rotor turns with it).
Json tree_with_ball_rotors(unsigned seed, int bodies) {
  Json doc = tree_with_rotors(seed, bodies, false);
  for (std::size_t b = 0; b < doc["bodies"].size(); b += 3) {
    Json& j = doc["bodies"][b]["joint"];
    j["type"] = "spherical";
    j.erase("axis");
    j.erase("gear");
    j.erase("limits");
  }
  return doc;
}

TEST_CASE("armature on a spherical joint: I_a on each of its rates, on every route",
          "[actuators]") {
  // As MuJoCo's dof_armature on a ball (tests/data/mjcf/features.xml compares with it): the
  // articulated-body recursion adds it to the joint's 3 × 3 D, the other routes to M^s.
  for (unsigned seed = 1; seed <= 3; ++seed) {
    INFO("seed " << seed);
    const Json doc = tree_with_ball_rotors(seed, 8), plain = without_rotors(doc);
    for (const RouteChoice& r : {RouteChoice{}, RouteChoice{.mass = MassRoute::Transform,
                                                .force = ForceRoute::Nodes,
                                                .dynamics = DynamicsRoute::Cholesky}}) {
      const Model a = on_route(doc, r), b = on_route(plain, r);
      REQUIRE(a.n_q() > a.n());  // (a quaternion: a spherical joint)
      CHECK(a.has_armature);
      check_rotors(a, b, seed);
      Workspace wa(a), wr(a);
      std::mt19937 rng(seed);
      const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng),
                 tau = random_uniform(a.n(), 3, rng);
      REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
      evaluate(a, wr, q, qd, tau);
      const VecX qdd = wr.Ms.llt().solve(wr.Q - wr.h);  // the plain solve of M^s q̈ = Q − h
      CHECK(rel_error(wa.qdd, qdd) < 1e-10);
    }
  }
}

// tree_with_rotors with free joints in place of some (their rotors I_a on all six rates, no gear):
// the root (a floating base) unless `couplings` name it, and bodies 2 and 6.
Json tree_with_free_rotors(unsigned seed, int bodies, bool couplings) {
  Json doc = tree_with_rotors(seed, bodies, couplings);
  for (const std::size_t b : {std::size_t{0}, std::size_t{2}, std::size_t{6}}) {
    if (b >= doc["bodies"].size() || (couplings && b == 0)) continue;
    Json& j = doc["bodies"][b]["joint"];
    j = {{"name", j["name"]}, {"type", "free"}, {"armature", 0.05 * (1 + b)}};
  }
  return doc;
}

// h_a − h_b on `a`'s free joints' linear rates is I_a ω × v (core/joints/rotor.hpp), read off
// the coordinate names; 0 on every other rate.
VecX free_rotor_bias(const Model& a, const VecX& qd) {
  VecX h = VecX::Zero(a.n());
  for (const Body& body : a.bodies) {
    const Joint& J = body.joint;
    if (J.type != JointType::Free || J.armature == 0) continue;
    const auto at = [&](const char* rate) {
      const auto& names = a.coordinate_names;
      return std::find(names.begin(), names.end(), J.name + "." + rate) - names.begin();
    };
    const Vec3 v(qd[at("vx")], qd[at("vy")], qd[at("vz")]),
        w(qd[at("wx")], qd[at("wy")], qd[at("wz")]);
    const Vec3 f = J.armature * w.cross(v);
    h[at("vx")] = f[0], h[at("vy")] = f[1], h[at("vz")] = f[2];
  }
  return h;
}

TEST_CASE("armature on a free joint: I_a on its six rates and I_a ω × v in h, on every route",
          "[actuators]") {
  const std::vector<RouteChoice> routes = main_routes();
  // `b` has no rotor; `c` only the free joints' removed (a law's coupled rotors add to h too).
  const auto check = [](const Model& a, const Model& b, const Model& c, unsigned seed) {
    check_rotors(a, b, seed);
    Workspace wa(a), wb(c);
    std::mt19937 rng(seed + 10);
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng);
    evaluate(a, wa, q, qd, VecX());
    evaluate(c, wb, q, qd, VecX());
    const VecX expected = free_rotor_bias(a, qd);
    REQUIRE(expected.norm() > 1e-2);
    CHECK(rel_error(wa.h - wb.h, expected, wb.h.cwiseAbs().maxCoeff()) < 1e-12);
  };
  for (unsigned seed = 1; seed <= 3; ++seed) {
    INFO("seed " << seed);
    const Json doc = tree_with_free_rotors(seed, 9, false), plain = without_rotors(doc);
    for (const RouteChoice& r : routes) {
      const Model a = on_route(doc, r), b = on_route(plain, r);
      REQUIRE(a.free_rotors.size() == 3);
      check(a, b, b, seed);
    }
  }
  // Linear couplings (C ≠ I) and a nonlinear law (the tree's equations hold the rotors).
  const Json coupled = tree_with_free_rotors(4, 8, true);
  const Model coupled_bare = load_text(without_rotors(coupled).dump());
  check(load_text(coupled.dump()), coupled_bare, coupled_bare, 4);
  Json law = Json::parse(nonlinear_coupled_tree_json(3));
  for (Json& body : law["bodies"]) body["joint"]["armature"] = 0.05, body["joint"]["gear"] = 4;
  law["bodies"].push_back(Json::parse(R"({"name": "drifter", "parent": "b5", "joint": {"name": "f",
      "type": "free", "armature": 0.2}, "elements": [{"type": "rigid_body", "mass": 2,
      "com": [0.1, -0.05, 0.2], "inertia": {"ixx": 0.03, "iyy": 0.02, "izz": 0.04}}]})"));
  const Model a = load_text(law.dump()), b = load_text(without_rotors(law).dump());
  law["bodies"].back()["joint"].erase("armature");
  const Model c = load_text(law.dump());
  REQUIRE(a.coupling_level);
  REQUIRE(a.tree->free_rotors.size() == 1);
  check(a, b, c, 3);
}

TEST_CASE(
    "armature on a floating base: the momentum conjugate to translation, P + I_a ṗ, is "
    "conserved",
    "[actuators]") {
  // Noether: in zero gravity with no outside force, L = T is unchanged by a translation of the
  // whole mechanism, so ∂T/∂ṗ = P + I_a ṗ (the bodies' momentum and the root rotor's, ṗ = R v the
  // root's world velocity) is constant. Without the rotor's ω × v term it drifts by I_a ω × v.
  Json doc = tree_with_free_rotors(5, 7, false);
  doc["gravity"] = {0, 0, 0};
  const Model m = load_text(doc.dump());
  const double Ia = m.bodies[0].joint.reflected_inertia;
  REQUIRE(Ia > 0);
  std::mt19937 rng(5);
  const VecX q0 = random_posture(m, rng), v0 = random_uniform(m.n(), 1.5, rng);
  const auto conjugate = [&](const VecX& q, const VecX& v) {
    Workspace ws(m);
    MomentumKinematics k;
    momentum_kinematics(m, ws, q, v, k);
    return Vec3(k.momentum.head<3>() + Ia * ws.body[0].R * v.head<3>());
  };
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-12;
  o.adaptive.atol = 1e-12;
  auto integ = make_integrator(m, o);
  integ->reset(0, q0, v0);
  REQUIRE(integ->advance_to(2.0).ok);
  const Vec3 p0 = conjugate(q0, v0), p1 = conjugate(integ->q(), integ->qd());
  CAPTURE(p0.transpose(), p1.transpose());
  CHECK((p1 - p0).norm() < 1e-8 * p0.norm());
  // The rotor matters here: the bodies' momentum P alone is not conserved.
  Workspace ws(m);
  MomentumKinematics k0, k1;
  momentum_kinematics(m, ws, q0, v0, k0);
  momentum_kinematics(m, ws, integ->q(), integ->qd(), k1);
  CHECK((k1.momentum.head<3>() - k0.momentum.head<3>()).norm() > 1e-4 * p0.norm());
}

TEST_CASE("damping on spherical and free joints: −c on each rate on every route, power −c|θ̇|²",
          "[actuators]") {
  // As MuJoCo's dof_damping on ball and free joints (tests/data/mjcf/floating.xml compares with
  // it), and Simbody's MobilityLinearDamper on each u of Ball and Free (the twin, below).
  Json doc = tree_with_free_rotors(6, 8, false);
  for (Json& b : doc["bodies"])
    if (b["joint"]["type"] == "free") b["joint"]["damping"] = 0.3;
  doc["bodies"][4]["joint"] = {{"name", "ball"}, {"type", "spherical"}, {"damping", 0.2}};
  Json plain = doc;
  for (Json& b : plain["bodies"])
    if (b["joint"]["type"] != "revolute" && b["joint"]["type"] != "prismatic")
      b["joint"].erase("damping");
  for (const RouteChoice& r : {RouteChoice{}, RouteChoice{.mass = MassRoute::Transform,
                                              .force = ForceRoute::Nodes,
                                              .dynamics = DynamicsRoute::Cholesky}}) {
    const Model a = on_route(doc, r), b = on_route(plain, r);
    REQUIRE(a.rate_dampers.size() == 4);
    Workspace wa(a), wb(b);
    std::mt19937 rng(6);
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng),
               tau = random_uniform(a.n(), 3, rng);
    evaluate(a, wa, q, qd, tau);
    evaluate(b, wb, q, qd, tau);
    VecX expected = VecX::Zero(a.n());  // −c on each rate of the damped joints, by name
    for (std::size_t k = 0; k < a.coordinate_names.size(); ++k) {
      const std::string& name = a.coordinate_names[k];
      const std::string joint = name.substr(0, name.find('.'));
      for (const Body& body : a.bodies)
        if (body.joint.name == joint && body.joint.nv > 1)
          expected[k] = -body.joint.damping * qd[k];
    }
    CHECK(rel_error(wa.Q - wb.Q, expected, wb.Q.cwiseAbs().maxCoeff()) < 1e-13);
    CHECK(rel_error(wa.h, wb.h) < 1e-14);
    const MatX Ms = wa.Ms;
    const VecX h = wa.h, Q = wa.Q;
    REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
    CHECK(rel_error(Ms * wa.qdd + h, Q) < 1e-9);
    inverse_dynamics(a, wa, q, qd, wa.qdd);
    CHECK(rel_error(wa.tau, tau, Ms.cwiseAbs().maxCoeff() * wa.qdd.cwiseAbs().maxCoeff()) < 1e-9);
  }
  // The energy balance of a run: E − E₀ = ∫ P dt with P = −Σ c |θ̇_j|² (and no other work), to
  // the integrator's tolerance; the model loses energy.
  doc["gravity"] = {0, 0, -9.81};
  const Model m = load_text(doc.dump());
  std::mt19937 rng(8);
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-11;
  o.adaptive.atol = 1e-12;
  auto integ = make_integrator(m, o);
  integ->reset(0, random_posture(m, rng), random_uniform(m.n(), 1, rng));
  REQUIRE(integ->advance_to(1.0).ok);
  const double E1 = integ->motion().energy_at(integ->y().data()).total(),
               E0 = integ->divergence().initial().total();
  CHECK(integ->work() < -1e-2);
  CHECK(std::abs(E1 - E0 - integ->work()) < 1e-7 * std::abs(integ->work()));
}

TEST_CASE("damping on spherical and free joints agrees with Simbody's dampers on Ball and Free",
          "[actuators][validation]") {
  Scratch s("rate_dampers");
  Json doc = Json::parse(mixed_tree_json(3, 7, 0.4, false, true));
  int damped = 0;
  for (Json& b : doc["bodies"])
    if (b["joint"]["type"] == "spherical" || b["joint"]["type"] == "free")
      b["joint"]["damping"] = 0.05 * ++damped;
  REQUIRE(damped >= 2);
  const std::string path = (s.dir / "damped.json").string();
  std::ofstream(path) << doc.dump();
  const Run r = run("validate " + path + " --budget 60 --t-end 0.3");
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("PASS") && !Catch::Contains("FAIL") &&
                        !Catch::Contains("not compared"));
}

TEST_CASE("armature: a spring arm oscillates at sqrt(k / (I + I_a G²)), its energy conserved",
          "[actuators]") {
  // 1 kg·m² on a spring k = 4 behind a rotor of 0.01 kg·m² at gear 10: I = 1 + 1 = 2, ω = √2.
  const Model m = load_text(arm(4, {{"armature", 0.01}, {"gear", 10}}).dump());
  const double T = 2 * std::numbers::pi / std::sqrt(2.0);
  const End half = run_to(m, 0.1, 0, T / 2), full = run_to(m, 0.1, 0, T);
  CHECK(half.q == Approx(-0.1).margin(1e-8));
  CHECK(full.q == Approx(0.1).margin(1e-8));
  CHECK(std::abs(full.qd) < 1e-8);
  // E = ½ (I + I_a G²) θ̇² + ½ k θ² is conserved (W = 0).
  CHECK(std::abs(half.balance) < 1e-10);
  // The maximal rate, at θ = 0: ½ 2 θ̇² = ½ 4 0.1².
  const End quarter = run_to(m, 0.1, 0, T / 4);
  CHECK(std::abs(quarter.qd) == Approx(0.1 * std::sqrt(2.0)).epsilon(1e-8));
}

TEST_CASE("Coulomb friction: a block decelerates at F_c / m and stops, E − E0 = W", "[actuators]") {
  // F_c = 2 N on 1 kg from 1 m/s: v = 1 − 2t until t = 0.5, x = t − t²; it stops at 0.25 m.
  const Model m = load_text(block({{"friction", 2.0}, {"friction_velocity", 0.01}}).dump());
  CHECK(m.bodies[0].joint.friction == 2.0);
  Workspace ws(m);
  for (const double v : {1.0, -0.3, 0.004, 0.0}) {
    REQUIRE(forward_dynamics(m, ws, VecX::Zero(1), VecX::Constant(1, v), VecX::Zero(1)).ok);
    CHECK(ws.qdd[0] == Approx(-2 * std::tanh(v / 0.01)).margin(1e-14));
  }
  const End mid = run_to(m, 0, 1, 0.25);
  CHECK(mid.qd == Approx(0.5).margin(1e-9));
  CHECK(mid.q == Approx(0.1875).margin(1e-9));
  // Past the stop the regularised law lets it creep by about v_s² m / F_c: 5e-5 m.
  const End end = run_to(m, 0, 1, 1.0);
  CHECK(end.q == Approx(0.25).margin(2e-4));
  CHECK(std::abs(end.qd) < 1e-6);
  // The friction's work is W: E − E0 − W stays at round-off, on a 0.5 J scale.
  CHECK(std::abs(end.balance) < 1e-9);
}

TEST_CASE("an enforced stop: a block bounces off it after half a period of sqrt(k / m)",
          "[actuators]") {
  // At 1 m/s into a stop at x = 0.1 of k = 1e4 N/m, no dissipation: in contact for π/100 s,
  // back out at −1 m/s.
  const Model m = load_text(
      block({{"limits", {-1, 0.1}}, {"stop", {{"stiffness", 1e4}, {"dissipation", 0}}}}).dump());
  const double t = 0.1 + std::numbers::pi / 100 + 0.05;
  const End e = run_to(m, 0, 1, t);
  CHECK(e.qd == Approx(-1).margin(1e-7));
  CHECK(e.q == Approx(0.05).margin(1e-7));
  CHECK(std::abs(e.balance) < 1e-9);
  // The deepest point: x = 0.1 + v / ω = 0.11 at π/200 s into the stop, at rest, all the
  // energy in the stop's potential ½ k_s 0.01² = 0.5 J.
  const End deepest = run_to(m, 0, 1, 0.1 + std::numbers::pi / 200);
  CHECK(deepest.q == Approx(0.11).margin(1e-7));
  CHECK(std::abs(deepest.qd) < 1e-5);
  CHECK(std::abs(deepest.balance) < 1e-9);
  // With Hunt–Crossley dissipation d = 2 it comes back slower, and the balance still holds.
  const Model lossy = load_text(
      block({{"limits", {-1, 0.1}}, {"stop", {{"stiffness", 1e4}, {"dissipation", 2}}}}).dump());
  const End l = run_to(lossy, 0, 1, t);
  CHECK(l.qd < -0.3);
  CHECK(l.qd > -0.5);
  CHECK(std::abs(l.balance) < 1e-9);
  // The law at 0.01 past either limit: −k_s x (1 ± d θ̇), clamped so that it never pulls the
  // joint into the stop (leaving it faster than 1/d: no force).
  Workspace ws(lossy);
  const auto qdd = [&](double x, double v) {
    REQUIRE(
        forward_dynamics(lossy, ws, VecX::Constant(1, x), VecX::Constant(1, v), VecX::Zero(1)).ok);
    return ws.qdd[0];
  };
  CHECK(qdd(0.11, -0.2) == Approx(-1e4 * 0.01 * (1 - 0.4)).epsilon(1e-12));
  CHECK(qdd(0.11, 0.2) == Approx(-1e4 * 0.01 * (1 + 0.4)).epsilon(1e-12));
  CHECK(qdd(0.11, -1) == 0);
  CHECK(qdd(-1.01, 0.2) == Approx(1e4 * 0.01 * (1 - 0.4)).epsilon(1e-12));
  CHECK(qdd(-1.01, 1) == 0);
  CHECK(qdd(0.05, 3) == 0);  // inside the limits
}

TEST_CASE("joint forces and rotors against finite differences: dE/dt = P_nc", "[actuators]") {
  // A random tree with rotors, springs, dampers, Coulomb friction and stops pressed into:
  // (E(y + δ ẏ) − E(y − δ ẏ)) / 2δ is the power of the non-conservative forces.
  Json doc = tree_with_rotors(6, 7, false);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  for (Json& b : doc["bodies"]) {
    Json& j = b["joint"];
    j["friction"] = u(rng);
    j["friction_velocity"] = 0.5;
    j["damping"] = 0.1 * u(rng);
    j["spring"] = {{"stiffness", u(rng)}, {"rest", 0.1}};
    j["limits"] = {-0.2, 0.2};
    j["stop"] = {{"stiffness", 50 * u(rng)}, {"dissipation", u(rng)}};
  }
  const Model m = load_text(doc.dump());
  Workspace ws(m);
  std::mt19937 states(1);
  for (int k = 0; k < 4; ++k) {
    const VecX q = random_uniform(m.n(), 0.6, states), qd = random_uniform(m.n(), 1.5, states),
               tau = random_uniform(m.n(), 1, states);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    const VecX qdd = ws.qdd;
    const double P = nonconservative_power(m, ws, qd, tau);
    const double d = 1e-5;
    const double Ep = energy(m, ws, q + d * qd, qd + d * qdd).total();
    const double Em = energy(m, ws, q - d * qd, qd - d * qdd).total();
    CHECK((Ep - Em) / (2 * d) == Approx(P).margin(1e-6 * (1 + std::abs(P))));
  }
}

TEST_CASE("effort limits: τ saturated at ±effort, evaluations and steps counted", "[actuators]") {
  // The arm (1 kg·m², no gravity) asked for τ = 5 N·m with an effort limit of 2: θ = t².
  const Model m = load_text(arm(0, {{"effort_limit", 2.0}}).dump());
  REQUIRE(m.has_effort_limits);
  const Actuation push = [](double, VecX& tau) { tau = VecX::Constant(1, 5.0); };
  const End e = run_to(m, 0, 0, 1.0, push);
  CHECK(e.q == Approx(1.0).epsilon(1e-9));
  CHECK(e.qd == Approx(2.0).epsilon(1e-9));
  CHECK(e.saturated_evaluations == e.evaluations);
  CHECK(std::abs(e.balance) < 1e-9);  // the work is that of the saturated τ
  // Within the limit nothing is saturated: τ = 1.5 gives θ = 0.75 t².
  const End within = run_to(m, 0, 0, 1.0, [](double, VecX& tau) { tau = VecX::Constant(1, 1.5); });
  CHECK(within.q == Approx(0.75).epsilon(1e-9));
  CHECK(within.saturated_evaluations == 0);
  // A recorded run counts the steps and names the coordinate.
  IntegratorOptions o;
  o.kind = IntegratorKind::Rk4;
  o.fixed.dt = 0.01;
  auto integ = make_integrator(m, o, push);
  integ->reset(0, VecX::Zero(1), VecX::Zero(1));
  const RecordedRun r = run_recorded(
      *integ, 0.5, 10, nullptr, [](const Integrator&, const Energy&) {},
      [](double) { return false; });
  REQUIRE(r.status.ok);
  CHECK(r.saturated_steps == 50);
  CHECK(r.saturated_evaluations == integ->stats().rhs_evals);  // every one
  CHECK(r.saturated_evaluations >= 200);                       // 4 a step
  REQUIRE(r.saturations.size() == 1);
  CHECK(r.saturations[0].name == "theta");
  CHECK(r.saturations[0].limit == 2.0);
  CHECK(r.saturations[0].evaluations == r.saturated_evaluations);
}

TEST_CASE("velocity limits and limit crossings are reported: which joint, when", "[actuators]") {
  // τ = 1 on 1 kg·m²: θ̇ = t passes the velocity limit 0.505 at t = 0.505, θ = t²/2 the upper
  // limit 0.2 at t = √0.4; the steps of 0.01 after find them.
  const Model m = load_text(arm(0, {{"velocity_limit", 0.505}, {"limits", {-1, 0.2}}}).dump());
  IntegratorOptions o;
  o.kind = IntegratorKind::Rk4;
  o.fixed.dt = 0.01;
  auto integ = make_integrator(m, o, [](double, VecX& tau) { tau = VecX::Constant(1, 1.0); });
  integ->reset(0, VecX::Zero(1), VecX::Zero(1));
  const RecordedRun r = run_recorded(
      *integ, 1.0, 10, nullptr, [](const Integrator&, const Energy&) {},
      [](double) { return false; });
  REQUIRE(r.velocity_excesses.size() == 1);
  CHECK(r.velocity_excesses[0].name == "theta");
  CHECK(r.velocity_excesses[0].t == Approx(0.51).margin(1e-9));
  CHECK(r.velocity_excesses[0].value == Approx(0.51).margin(1e-9));
  CHECK(r.velocity_excesses[0].limit == 0.505);
  REQUIRE(r.limit_crossings.size() == 1);
  CHECK(r.limit_crossings[0].name == "theta");
  CHECK(r.limit_crossings[0].t == Approx(0.64).margin(1e-9));  // the first step past √0.4
}

TEST_CASE("bad actuator input: one line naming the file, the JSON path and the problem",
          "[actuators][errors]") {
  const auto error = [](const Json& joint) { return text_error(block(joint).dump()); };
  CHECK_THAT(error({{"armature", -1}}),
             Catch::Contains("/bodies/0/joint/armature") && Catch::Contains("negative"));
  CHECK_THAT(error({{"gear", 0}}),
             Catch::Contains("/bodies/0/joint/gear") && Catch::Contains("not zero"));
  CHECK_THAT(error({{"friction", -0.5}}),
             Catch::Contains("/bodies/0/joint/friction") && Catch::Contains("negative"));
  CHECK_THAT(error({{"friction_velocity", 0}}),
             Catch::Contains("/bodies/0/joint/friction_velocity") && Catch::Contains("positive"));
  CHECK_THAT(error({{"effort_limit", 0}}),
             Catch::Contains("/bodies/0/joint/effort_limit") && Catch::Contains("positive"));
  CHECK_THAT(error({{"velocity_limit", -2}}),
             Catch::Contains("/bodies/0/joint/velocity_limit") && Catch::Contains("positive"));
  CHECK_THAT(error({{"stop", Json::object()}}),
             Catch::Contains("/bodies/0/joint/stop") && Catch::Contains("limits"));
  CHECK_THAT(error({{"limits", {0.3, -0.3}}, {"stop", Json::object()}}),
             Catch::Contains("/bodies/0/joint/limits") && Catch::Contains("lower > upper"));
  CHECK_THAT(error({{"limits", {-1, 1}}, {"stop", {{"stiffness", 0}}}}),
             Catch::Contains("/bodies/0/joint/stop/stiffness") && Catch::Contains("positive"));
  CHECK_THAT(error({{"limits", {-1, 1}}, {"stop", {{"damping", 1}}}}),
             Catch::Contains("/bodies/0/joint/stop") && Catch::Contains("damping"));
  for (const std::string& e : {error({{"armature", -1}}), error({{"gear", 0}})})
    CHECK(e.find('\n') == std::string::npos);
  // A NaN (the Builder's way in; JSON has none): refused at compile, naming the field.
  MechanismBuilder builder("m");
  JointSpec j;
  j.type = JointType::Revolute;
  j.armature = NAN;
  builder.body("a", "world", j);
  builder.lumped_point("a", Vec3(1, 0, 0), 1.0);
  CHECK_THROWS_WITH(builder.build(),
                    Catch::Contains("/bodies/0/joint/armature") && Catch::Contains("NaN"));
  // A spherical joint takes none of them but its rotor.
  CHECK_THAT(text_error(R"({"name": "b", "bodies": [{"name": "a", "parent": "world",
      "joint": {"type": "spherical", "gear": 2}, "elements": [{"type": "rigid_body",
      "mass": 1, "com": [0, 0, 0], "inertia": {"ixx": 1, "iyy": 1, "izz": 1}}]}]})"),
             Catch::Contains("only joints of one coordinate"));
  // A fixed joint none either.
  CHECK_THAT(text_error(R"({"name": "b", "bodies": [{"name": "a", "parent": "world",
      "joint": {"type": "fixed", "friction": 0.1}, "elements": [{"type": "lumped_point",
      "node": [0, 0, 0], "mass": 1}]}]})"),
             Catch::Contains("/bodies/0/joint/friction") && Catch::Contains("fixed joint"));
}

TEST_CASE("check sees a stiff stop and the friction's slope", "[actuators][check]") {
  Scratch s("actuators_check");
  const auto rk4_step = [&](const Json& doc) {
    std::ofstream(s / "m.json") << doc.dump();
    const Run r = run("check " + (s / "m.json") + " --json --states 2");
    const Json j = Json::parse(r.out);
    return std::pair{j["largest_stable_step"]["rk4"], j["stop_states"].get<int>()};
  };
  // A 1 kg block: nothing limits the step; pressed into a stop of 1e4 N/m, ω = 100 rad/s and
  // RK4's limit h ω ≤ 2√2; regularised friction of slope F_c / v_s = 200 1/s, h ≤ 2.785 / 200.
  const auto [free_step, none] = rk4_step(block(Json::object()));
  CHECK(free_step.is_null());
  CHECK(none == 0);
  const auto [stop_step, one] =
      rk4_step(block({{"limits", {-1, 0.1}}, {"stop", {{"stiffness", 1e4}, {"dissipation", 0}}}}));
  CHECK(one == 1);
  CHECK(stop_step.get<double>() == Approx(2 * std::sqrt(2.0) / 100).epsilon(1e-3));
  const auto [friction_step, zero] =
      rk4_step(block({{"friction", 2.0}, {"friction_velocity", 0.01}}));
  CHECK(zero == 0);
  CHECK(friction_step.get<double>() == Approx(2.785 / 200).epsilon(1e-3));
}

TEST_CASE("info lists each joint's rotor, friction, limits and stop", "[actuators][cli]") {
  Scratch s("actuators_info");
  std::ofstream(s / "m.json") << block({{"limits", {-1, 0.1}},
                                        {"stop", {{"stiffness", 1e4}, {"dissipation", 0.2}}},
                                        {"friction", 2.0},
                                        {"armature", 0.01},
                                        {"gear", 10},
                                        {"effort_limit", 30},
                                        {"velocity_limit", 3}})
                                     .dump();
  const Run text = run("info " + (s / "m.json"));
  REQUIRE(text.code == 0);
  CHECK_THAT(text.out, Catch::Contains("limits [-1, 0.1] with a stop (k 10000, d 0.2); Coulomb "
                                       "friction 2 (v_s 0.01); rotor 0.01 x gear 10^2 = 1; "
                                       "effort 30; velocity 3"));
  const Run json = run("info " + (s / "m.json") + " --json");
  REQUIRE(json.code == 0);
  const Json j = Json::parse(json.out)["joints"][0];
  CHECK(j["armature"]["reflected"].get<double>() == Approx(1.0).epsilon(1e-15));
  CHECK(j["stop"]["dissipation"] == 0.2);
  CHECK(j["limits"][1] == 0.1);
  CHECK(j["effort_limit"] == 30);
}

TEST_CASE("a coupled joint's effort limit is kept, not applied, and a run says so",
          "[actuators][urdf]") {
  // The hand's distal joints mimic the middle ones: their <limit effort> has no τ to saturate.
  const Model m = load_model(model_path("urdf/hand16.urdf"));
  IntegratorOptions o;
  o.kind = IntegratorKind::Rk4;
  o.fixed.dt = 1e-4;
  auto integ = make_integrator(m, o);
  integ->reset(0, VecX::Zero(m.n()), VecX::Zero(m.n()));
  const RecordedRun r = run_recorded(
      *integ, 1e-3, 10, nullptr, [](const Integrator&, const Energy&) {},
      [](double) { return false; });
  REQUIRE(r.status.ok);
  CHECK(r.unapplied_effort_limits ==
        std::vector<std::string>{"index_dip", "middle_dip", "ring_dip", "little_dip"});
  // The coordinates' own limits are applied.
  CHECK(m.has_effort_limits);
  CHECK(m.effort_limit.allFinite());
}

TEST_CASE("simulate warns of saturation, velocity limits and limits left, and --json has them",
          "[actuators][cli]") {
  Scratch s("actuators_simulate");
  std::ofstream(s / "arm.json")
      << arm(0, {{"effort_limit", 2.0}, {"velocity_limit", 1.01}, {"limits", {-1, 0.5}}}).dump();
  const std::string args =
      "simulate " + (s / "arm.json") + " --t-end 1 --integrator rk4 --dt 0.01 --tau 5";
  const Run text = run(args);
  CHECK(text.code == 0);
  CHECK_THAT(
      text.out,
      Catch::Contains("warning: joint 'theta' exceeded its velocity limit 1.01 at t = 0.51 "
                      "s (rate 1.02)") &&
          Catch::Contains("warning: joint 'theta' left its limits [-1, 0.5] at t = 0.71 s") &&
          Catch::Contains("limits are not enforced") &&
          Catch::Contains("warning: tau saturated at the effort limits in") &&
          Catch::Contains("and 100 steps (theta at ±2: "));
  const Run js = run(args + " --json 2>/dev/null");
  const Json j = Json::parse(js.out);
  CHECK(j["saturated_steps"] == 100);
  CHECK(j["saturated_evaluations"] == j["rhs_evals"]);
  CHECK(j["saturations"][0]["coordinate"] == "theta");
  CHECK(j["velocity_excesses"][0]["t"].get<double>() == Approx(0.51).margin(1e-9));
  CHECK(j["limit_crossings"][0]["t"].get<double>() == Approx(0.71).margin(1e-9));
  CHECK(j["unapplied_effort_limits"].empty());
  // With a stop the crossing is said to be into a compliant stop, not unenforced.
  std::ofstream(s / "stop.json")
      << arm(0, {{"limits", {-1, 0.5}}, {"stop", Json::object()}}).dump();
  CHECK_THAT(run("simulate " + (s / "stop.json") + " --t-end 1 --tau 5").out,
             Catch::Contains("its stop is compliant"));
}
