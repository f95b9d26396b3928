// The analytic derivatives of the dynamics (core/derivatives/derivatives.hpp) against independent
// numbers: central differences along the tangent q ⊕ ε e_m (step 1e-6: truncation ~1e-12, round-off
// ~1e-10 of the scale) and a Richardson extrapolation of them (steps 1e-3 and 5e-4: error
// O(h⁴)); against the tensor D (∂h/∂v = (D + D over its last two indices swapped) q̇); and
// ∂q̈/∂τ M^s = I. On seeded random trees of every joint type with springs, dampers, Coulomb
// friction, rotors, stops, loads and couplings, and on the bundled and URDF robots.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "core/derivatives/derivatives.hpp"
#include "tests/differences.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;

namespace {

// Every joint of one coordinate gets, by a seeded draw, Coulomb friction, a rotor, a stop.
std::string with_actuators(const std::string& text, unsigned seed) {
  Json j = Json::parse(text);
  std::mt19937 rng(seed);
  for (Json& b : j["bodies"]) {
    Json& joint = b["joint"];
    if (joint["type"] != "revolute" && joint["type"] != "prismatic") continue;
    if (rng() % 2) joint["friction"] = 0.4, joint["friction_velocity"] = 0.7;
    if (rng() % 2) joint["armature"] = 0.02, joint["gear"] = 3;
    if (rng() % 3 == 0)
      joint["limits"] = {-0.4, 0.4}, joint["stop"] = {{"stiffness", 50}, {"dissipation", 0.1}};
  }
  return j.dump();
}

// `count` two-point springs between random bodies (or the world) at random points, with seeded
// stiffness, rest length and damping (core/dynamics/springs.hpp).
std::string with_springs(const std::string& text, unsigned seed, int count) {
  Json j = Json::parse(text);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.0, 1.0);
  const auto v3 = [&](double s) { return Json::array({s * u(rng), s * u(rng), s * u(rng)}); };
  const int nb = static_cast<int>(j["bodies"].size());
  const auto end = [&](int b) {
    return b < 0 ? Json{{"body", "world"}, {"xyz", v3(1.0)}}
                 : Json{{"body", j["bodies"][b]["name"]}, {"xyz", v3(0.3)}};
  };
  Json springs = Json::array();
  for (int s = 0; s < count; ++s) {
    const int a = static_cast<int>(rng() % nb);  // and b another body, or the world (−1)
    int b = static_cast<int>(rng() % nb) - 1;
    if (b >= a) ++b;
    springs.push_back({{"a", end(a)},
                       {"b", end(b)},
                       {"stiffness", 5 + 35 * pos(rng)},
                       {"rest_length", 0.6 * pos(rng)},
                       {"damping", s % 3 == 2 ? 0.0 : 1.5 * pos(rng)}});
  }
  j["springs"] = springs;
  return j.dump();
}

// The tree with its first body welded to the world and every fifth body hung from the world
// (seeded): (M^s)⁻¹ then falls into diagonal blocks, one per moving subtree off a fixed root.
std::string with_fixed_roots(const std::string& text) {
  Json j = Json::parse(text);
  Json& bodies = j["bodies"];
  bodies[0]["joint"] = {{"name", "j0"}, {"type", "fixed"}};
  for (std::size_t b = 3; b < bodies.size(); b += 5) bodies[b]["parent"] = "world";
  return j.dump();
}

// The number of diagonal blocks of `minv`: it must be exactly zero off them (a block is a run
// of rates whose entries couple none outside it).
int diagonal_blocks(const MatX& minv) {
  const Eigen::Index n = minv.rows();
  int blocks = 0;
  for (Eigen::Index first = 0; first < n;) {
    Eigen::Index end = first + 1;
    for (Eigen::Index r = first; r < end; ++r)  // grow while a rate couples one beyond
      for (Eigen::Index c = end; c < n; ++c)
        if (minv(r, c) != 0 || minv(c, r) != 0) end = c + 1;
    ++blocks;
    first = end;
  }
  return blocks;
}

// The worst relative error of each derivative against both differences.
struct Agreement {
  double central = 0, richardson = 0;
};

// `beyond`: how far (rad or m) the state may leave the joints' limits, so that stops engage; 0
// for a four-bar law, which may not assemble outside its input's range.
void check_model(const Model& m, unsigned seed, Agreement& worst, double beyond = 0.5) {
  Workspace ws(m), wf(m);
  DerivativeWorkspace d(m);
  std::mt19937 rng(seed);
  // Joints beyond their limits too (random_posture stays inside them): stops engaged.
  const VecX q = integrate_posture(m, random_posture(m, rng), random_uniform(m.n(), beyond, rng));
  const VecX v = random_uniform(m.n(), 1.5, rng), qdd = random_uniform(m.n(), 2, rng);
  // τ of a moderate q̈ (a given τ on a light finger would make q̈ ~1e6 and its differences noise).
  inverse_dynamics(m, wf, q, v, random_uniform(m.n(), 2, rng));
  const VecX tau = wf.tau;
  const Function tau_of = [&](const VecX& x, const VecX& y) {
    inverse_dynamics(m, wf, x, y, qdd);
    return wf.tau;
  };
  const Function qdd_of = [&](const VecX& x, const VecX& y) {
    REQUIRE(forward_dynamics(m, wf, x, y, tau).ok);
    return wf.qdd;
  };
  inverse_dynamics_derivatives(m, ws, d, q, v, qdd);
  const MatX dtau_dq = d.dtau_dq, dtau_dv = d.dtau_dv;
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, tau).ok);
  struct Case {
    const char* name;
    const MatX *analytic, *other;  // the function's other derivative, for the scale
    const Function* f;
    bool wrt_q;
  };
  for (const auto& [name, analytic, other, f, wrt_q] :
       {Case{"dtau_dq", &dtau_dq, &dtau_dv, &tau_of, true},
        Case{"dtau_dv", &dtau_dv, &dtau_dq, &tau_of, false},
        Case{"dqdd_dq", &d.dqdd_dq, &d.dqdd_dv, &qdd_of, true},
        Case{"dqdd_dv", &d.dqdd_dv, &d.dqdd_dq, &qdd_of, false}}) {
    INFO(name);
    const MatX c = central(m, *f, q, v, wrt_q, 1e-6), r = richardson(m, *f, q, v, wrt_q);
    // Relative to the larger of the function's two derivatives (∂τ/∂v of one hinge is 0).
    const double scale = std::max({r.cwiseAbs().maxCoeff(), other->cwiseAbs().maxCoeff(), 1e-12});
    const double ec = rel_error(*analytic, c, scale), er = rel_error(*analytic, r, scale);
    worst.central = std::max(worst.central, ec);
    worst.richardson = std::max(worst.richardson, er);
    // Central differences at h = 1e-6 carry the truncation h² f'''/6 and the round-off ε |f| / h
    // of f's own evaluation; measured up to 1.3e-7 (the space robot, whose q̈ dwarfs its
    // derivatives). Richardson's is the sharp check.
    CHECK(ec < 3e-7);
    CHECK(er < 1e-9);
  }
  // The products over ∂τ's non-zero rows and (M^s)⁻¹'s blocks (core/derivatives/inverse_mass.hpp)
  // against Eigen's dense product: up to n = 96 the same sums in another order (measured up to
  // 8e-14); above, solves on the factorisation (measured up to 3e-12).
  if (!m.coupling_level)
    for (const auto& [dqdd, dtau] : {std::pair{&d.dqdd_dq, &d.dtau_dq}, {&d.dqdd_dv, &d.dtau_dv}}) {
      const MatX dense = -(d.Minv * *dtau);
      const double e = rel_error(*dqdd, dense, std::max(dense.cwiseAbs().maxCoeff(), 1e-12));
      CHECK(e < (m.n() > 96 ? 1e-10 : 1e-12));
    }
  // ∂q̈/∂τ = (M^s)⁻¹: (M^s)⁻¹ M^s = I, to the round-off of an inverse, ε cond(M^s) (1e-10 was
  // reached on the 160-body coupled chain).
  mass_matrix(m, wf, q);
  const VecX lambda =
      Eigen::SelfAdjointEigenSolver<MatX>(wf.Ms, Eigen::EigenvaluesOnly).eigenvalues();
  const double cond = lambda.maxCoeff() / lambda.minCoeff();
  INFO("cond(M^s) = " << cond);
  CHECK(rel_error(d.Minv * wf.Ms, MatX::Identity(m.n(), m.n()), 1.0) <
        std::max(1e-10, 100 * std::numeric_limits<double>::epsilon() * cond));
}

}  // namespace

TEST_CASE("derivatives agree with differences on random trees of every joint type",
          "[derivatives]") {
  // Revolute, prismatic, fixed; universal, planar, spherical, free (odd seeds float); springs,
  // dampers, point loads and torques, gravity; friction, rotors and stops by with_actuators.
  Agreement worst;
  for (unsigned seed = 1; seed <= 8; ++seed)
    for (const int bodies : {1, 3, 8, 16}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const bool several = seed % 4 != 0;
      const Model m = load_text(with_actuators(
          mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, false, several), seed));
      check_model(m, seed, worst);
    }
  WARN("random trees: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences on a flexible bar on a hub", "[derivatives]") {
  // The bar's bodies and springs (io/flexible_bar.hpp) under gravity, with stiffness-
  // proportional damping, clamped to a turning hub: docs/flexible.md's "every derivative
  // applies as it is", checked. The rotary inertias keep cond(M^s) moderate: the differences'
  // round-off grows with it (with 100 times less, Richardson's error was 1.1e-9 in the
  // sanitizer build, above the shared 1e-9).
  Agreement worst;
  const Model m = load_text(R"({"name": "hub and bar", "gravity": [0.5, -1, -9.81], "bodies": [
    {"name": "hub", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "rigid_body", "mass": 2, "inertia": {"ixx": 0.1, "iyy": 0.1,
                   "izz": 0.2}}]}],
    "flexible_bars": [{"name": "arm", "parent": "hub", "length": 0.8, "segments": 3,
      "origin": {"xyz": [0.1, 0, 0], "rpy": [0, 0.2, 0]},
      "section": {"EA": 2e4, "EIy": 30, "EIz": 40, "GJ": 20, "rhoA": 0.5, "rhoIy": 1e-2,
                  "rhoIz": 2e-2},
      "damping": {"stiffness_proportional": 1e-3}}]})");
  for (unsigned seed = 1; seed <= 3; ++seed) check_model(m, seed, worst, 0.05);
  WARN("flexible bar: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences on coupled random trees", "[derivatives]") {
  Agreement worst;
  for (unsigned seed = 1; seed <= 6; ++seed)
    for (const int bodies : {6, 14}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const Model m = load_text(with_actuators(mixed_tree_json(seed, bodies, 0.5, true), seed));
      REQUIRE(!m.identity_coupling);
      check_model(m, seed, worst);
    }
  WARN("coupled trees: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences with rotors on spherical and free joints",
          "[derivatives]") {
  // The rotor enters D of the joint's block on the articulated route, and so (M^s)⁻¹; a free
  // joint's also h_a = I_a ω × v, whose ∂/∂v̇ is I_a [ω]× and ∂/∂ω −I_a [v]×.
  Agreement worst;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    Json doc = Json::parse(mixed_tree_json(seed, 9, 0.4, false, true));
    int balls = 0;
    for (Json& b : doc["bodies"])
      if (b["joint"]["type"] == "spherical" || b["joint"]["type"] == "free")
        b["joint"]["armature"] = 0.02 * ++balls;
    INFO("seed " << seed << ", " << balls << " spherical and free joints");
    const Model m = load_text(doc.dump());
    if (balls == 0) continue;
    REQUIRE(m.has_armature);
    check_model(m, seed, worst);
  }
  WARN("spherical and free rotors: central " << worst.central << ", Richardson "
                                             << worst.richardson);
}

TEST_CASE("derivatives agree with differences above the dense-product size", "[derivatives]") {
  // Above n = 96 ∂q̈ is formed by the factorisation instead of dense products with (M^s)⁻¹:
  // eight columns at a time on the articulated route, column by column on a coupled one.
  Agreement worst;
  for (const bool coupled : {false, true}) {
    INFO((coupled ? "coupled" : "uncoupled"));
    const Model m = load_text(mixed_tree_json(7, coupled ? 160 : 120, 0.0, coupled, false));
    REQUIRE(m.n() > 96);
    REQUIRE(m.identity_coupling != coupled);
    check_model(m, 7, worst);
  }
  WARN("n > 96: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences where (M^s)⁻¹ has diagonal blocks",
          "[derivatives][springs]") {
  // Subtrees that share no moving joint do not couple in M^s: the sweep forms and the products
  // read only the blocks. Checked on trees welded to the world (several blocks), with springs
  // across blocks (whose ∂τ/∂q couples them), and on the fixed-base Atlas and HyQ.
  Agreement worst;
  for (unsigned seed = 1; seed <= 6; ++seed)
    for (const int bodies : {7, 16}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      std::string text = with_fixed_roots(mixed_tree_json(seed, bodies, 0.4, false, seed % 2));
      if (seed > 3) text = with_springs(text, seed, 2);
      const Model m = load_text(text);
      DerivativeWorkspace d(m);
      REQUIRE(d.sweep.applies);
      check_model(m, seed, worst);
      Workspace ws(m);
      std::mt19937 rng(seed);
      const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
      REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, VecX::Zero(m.n())).ok);
      CHECK(diagonal_blocks(d.Minv) > 1);
    }
  const std::string robots = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/";
  // Atlas: the two legs and the torso; HyQ: its four legs.
  for (const auto& [name, blocks] : {std::pair{"atlas.urdf", 3}, std::pair{"hyq.urdf", 4}}) {
    INFO(name);
    const Model m = load_model(robots + name);
    check_model(m, 6, worst);
    Workspace ws(m);
    DerivativeWorkspace d(m);
    REQUIRE(forward_dynamics_derivatives(m, ws, d, VecX::Zero(m.n()), VecX::Ones(m.n()),
                                         VecX::Zero(m.n()))
                .ok);
    CHECK(diagonal_blocks(d.Minv) == blocks);
  }
  WARN("diagonal blocks: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences on the bundled and URDF robots", "[derivatives]") {
  Agreement worst;
  for (const char* name : {"finger.json", "finger_coupled.json", "hand.json", "space_robot.json"}) {
    INFO(name);
    check_model(load_model(model_path(name)), 3, worst);
  }
  const std::string robots = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/";
  check_model(load_model(robots + "iiwa.urdf"), 4, worst);
  check_model(load_model(robots + "atlas.urdf", {.floating_base = true}), 5, worst);
  WARN("robots: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences on random trees with two-point springs",
          "[derivatives][springs]") {
  // Springs between random bodies and the world, on trees of every joint type (odd seeds on a
  // free base), plain and with linear couplings: the springs' Q_s(q, v) on top of the rest.
  Agreement worst;
  for (unsigned seed = 1; seed <= 8; ++seed)
    for (const int bodies : {1, 4, 9}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const bool coupled = seed % 3 == 0 && bodies > 1;
      const Model m = load_text(
          with_springs(mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, coupled, !coupled), seed,
                       1 + bodies / 2));
      REQUIRE(m.springs.size() == static_cast<std::size_t>(1 + bodies / 2));
      check_model(m, seed, worst);
    }
  WARN("random trees with springs: central " << worst.central << ", Richardson "
                                             << worst.richardson);
}

TEST_CASE("derivatives agree with differences on the flyball governor's stiff couplers",
          "[derivatives][springs]") {
  // Two spring-dampers of 8e5 N/m and 4e4 N s/m from the slider to the rods.
  const Model m = load_model(model_path("iftomm_a05_flyball.json"));
  REQUIRE(m.springs.size() == 2);
  Agreement worst;
  for (unsigned seed = 1; seed <= 4; ++seed) check_model(m, seed, worst);
  WARN("flyball: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences on elements spanning bodies",
          "[derivatives][spans]") {
  // The four-bar fingers' trees (every joint a coordinate): their coupler rods join two bodies
  // that move apart there, so the rods' ends move on two paths and the rods' lengths change.
  Agreement worst;
  for (const char* name : {"finger_fourbar.json", "hand_fourbar.json"}) {
    INFO(name);
    const Model law = load_model(model_path(name));
    const Model& tree = *law.tree;
    REQUIRE_FALSE(tree.condensable);  // the rods
    for (unsigned seed = 1; seed <= 3; ++seed) check_model(tree, seed, worst);
  }
  // Rods across fixed joints on random trees (with springs, so the rods' nodes and the springs'
  // ends share paths).
  int rods = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    INFO("seed " << seed);
    const Model m = load_text(
        with_springs(with_rods(mixed_tree_json(seed, 12, 0.5, false, true), seed, rods), seed, 2));
    check_model(m, seed, worst);
  }
  CHECK(rods >= 4);
  WARN("spanning rods: central " << worst.central << ", Richardson " << worst.richardson);
}

TEST_CASE("derivatives agree with differences through nonlinear coupling laws",
          "[derivatives][laws]") {
  // Random trees whose joints follow others by a four-bar, a polynomial in two joints and a
  // spline of a coupled joint (the chain through θ = g(q): G, H and g's third derivatives).
  Agreement worst;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    INFO("seed " << seed);
    const Model m = load_text(nonlinear_coupled_tree_json(seed));
    REQUIRE(m.coupling_level);
    check_model(m, seed, worst, 0.0);
  }
  WARN("law-coupled trees: central " << worst.central << ", Richardson " << worst.richardson);
  Agreement bundled;
  for (const char* name : {"finger_fourbar.json", "hand_fourbar.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    REQUIRE(m.coupling_level);
    for (unsigned seed = 1; seed <= 3; ++seed) check_model(m, seed, bundled, 0.0);
  }
  WARN("finger_fourbar, hand_fourbar: central " << bundled.central << ", Richardson "
                                                << bundled.richardson);
}

// ∂τ/∂v(q, v) − ∂τ/∂v(q, 0) against Σ_c (D_abc + D_acb) q̇_c from `third_order_tensor` (the
// dampers' constant part cancels; no Coulomb friction, whose slope depends on q̇); returns
// ∂τ/∂v at q̇ = 0.
MatX check_against_tensor(const Model& m, unsigned seed) {
  for (const Body& b : m.bodies) REQUIRE(b.joint.friction == 0);
  Workspace ws(m);
  DerivativeWorkspace d(m);
  std::mt19937 rng(seed);
  const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.5, rng);
  const VecX qdd = random_uniform(m.n(), 2, rng);
  inverse_dynamics_derivatives(m, ws, d, q, VecX::Zero(m.n()), qdd);
  const MatX at_rest = d.dtau_dv;
  inverse_dynamics_derivatives(m, ws, d, q, v, qdd);
  const std::vector<MatX> D = third_order_tensor(m, ws, q);
  MatX contraction(m.n(), m.n());
  for (int a = 0; a < m.n(); ++a) contraction.row(a) = ((D[a] + D[a].transpose()) * v).transpose();
  CHECK(rel_error(d.dtau_dv - at_rest, contraction, contraction.cwiseAbs().maxCoeff()) < 1e-12);
  return at_rest;
}

TEST_CASE("dtau/dv is the contraction of the tensor D without dampers", "[derivatives]") {
  // ∂h/∂v_b = Σ_c (D_abc + D_acb) q̇_c; and ∂τ/∂v = 0 at q̇ = 0.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    INFO("seed " << seed);
    Json j = Json::parse(mixed_tree_json(seed, 7, 0.5, seed % 2 == 0));
    for (Json& b : j["bodies"]) b["joint"].erase("damping");
    CHECK(check_against_tensor(load_text(j.dump()), seed).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("dtau/dv is the contraction of the tensor D through coupling laws and spanning rods",
          "[derivatives][laws][spans]") {
  // The law chain's D (G, M_θ H) against the chain's ∂τ/∂v = Gᵀ (K_v G + 2 M_θ Θ); the node-level
  // D of the four-bar trees (their rods) against the rods' point terms.
  for (unsigned seed = 1; seed <= 4; ++seed) {
    INFO("seed " << seed);
    check_against_tensor(load_text(nonlinear_coupled_tree_json(seed)), seed);
  }
  for (const char* name : {"finger_fourbar.json", "hand_fourbar.json"}) {
    INFO(name);
    const Model law = load_model(model_path(name));
    check_against_tensor(law, 3);
    check_against_tensor(*law.tree, 3);
  }
}

TEST_CASE("linearization: A's chart block against differences of the chart rates",
          "[derivatives]") {
  // ∂ξ̇/∂ξ at ξ = 0 (spherical and free joints turn it), and A, B assembled from the forward
  // derivatives: A = [[∂ξ̇/∂ξ, I], [∂q̈/∂q, ∂q̈/∂v]], B = [0; (M^s)⁻¹ S] (S: the actuated
  // coordinates, all but the free joints' here).
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Model m = load_text(mixed_tree_json(seed, 10, 0.5, false, true));
    Workspace ws(m);
    DerivativeWorkspace d(m);
    std::mt19937 rng(seed);
    const int n = m.n();
    const VecX q = random_posture(m, rng), v = random_uniform(n, 1.5, rng);
    REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, VecX::Zero(n)).ok);
    MatX A, B;
    linearization(m, d, v, A, B);
    const double h = 1e-6;
    MatX chart(n, n);
    for (int k = 0; k < n; ++k)
      chart.col(k) = (chart_rates(m, q, h * VecX::Unit(n, k), v) -
                      chart_rates(m, q, -h * VecX::Unit(n, k), v)) /
                     (2 * h);
    CHECK(rel_error(A.topLeftCorner(n, n), chart, v.cwiseAbs().maxCoeff()) < 1e-8);
    CHECK(A.topRightCorner(n, n) == MatX::Identity(n, n));
    CHECK(A.bottomLeftCorner(n, n) == d.dqdd_dq);
    REQUIRE(B.cols() == m.n_actuated());
    for (int k = 0; k < m.n_actuated(); ++k) CHECK(B.col(k).tail(n) == d.Minv.col(m.actuated[k]));
    CHECK(B.topRows(n).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("derivatives refuse the models they do not cover in one line", "[derivatives]") {
  // closed loops over coupled joints
  Json j = Json::parse(read_file(model_path("finger_fourbar_loop.json")));
  j["couplings"] = Json::array({{{"joint", "dip"}, {"follows", "pip"}, {"ratio", 0.8}}});
  const Model loops = load_text(j.dump());
  CHECK_THROWS_WITH(DerivativeWorkspace(loops), Catch::Contains("closed loops"));
  const Model spans = load_model(model_path("finger_paper.json"));
  CHECK_THROWS_WITH(DerivativeWorkspace(spans), Catch::Contains("body-level form"));
}
