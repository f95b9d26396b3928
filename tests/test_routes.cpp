// The routes compile() chooses (Model::mass_route, force_route, dynamics_route, the mass solver)
// give the same equations: each new route is checked against the one it replaces, on random trees
// of every element type, with fixed joints, springs, dampers, loads and couplings, and at the sizes
// where the choice switches.
#include <Eigen/SVD>
#include <array>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "core/dynamics/articulated.hpp"
#include "core/workspace/mass_pattern.hpp"
#include "core/workspace/mass_solver.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;

namespace {

// q̈, M^s, h, Q and τ of `a` and `b` (the same mechanism on different routes) at random states.
void check_same_equations(const Model& a, const Model& b, unsigned seed, double tol) {
  Workspace wa(a), wb(b);
  std::mt19937 rng(seed);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng),
               tau = random_uniform(a.n(), 3, rng), qdd = random_uniform(a.n(), 3, rng);
    REQUIRE(tree_forward_dynamics(a, wa, q, qd, tau).ok);
    REQUIRE(tree_forward_dynamics(b, wb, q, qd, tau).ok);
    evaluate(b, wb, q, qd, tau);
    // q̈ by two backward-stable solves differs by up to ~ε cond(M^s) (a flexible bar's M^s
    // reaches 1e7); the assembled terms by round-off alone.
    const Eigen::VectorXd sv = Eigen::JacobiSVD<MatX>(wb.Ms).singularValues();
    const double tol_qdd = std::max(tol, 4 * 2.2e-16 * sv[0] / sv[sv.size() - 1]);
    CHECK(rel_error(wa.qdd, wb.qdd) < tol_qdd);
    evaluate(a, wa, q, qd, tau);
    CHECK(rel_error(wa.Ms, wb.Ms) < tol);
    // h vanishes for one joint: relative to the size of its terms, ‖M^s‖ ‖q̇‖², not to itself.
    CHECK(rel_error(wa.h, wb.h, wb.Ms.cwiseAbs().maxCoeff() * qd.squaredNorm()) < tol);
    CHECK(rel_error(wa.Q, wb.Q) < tol);
    const MatX Ms = wb.Ms;
    mass_matrix(a, wa, q);  // M^s alone
    CHECK(rel_error(wa.Ms, Ms) < tol);
    // q̈ solves the assembled equations.
    CHECK(rel_error(wb.Ms * wa.qdd + wb.h, wb.Q) < tol_qdd);
    inverse_dynamics(a, wa, q, qd, qdd);
    inverse_dynamics(b, wb, q, qd, qdd);
    CHECK(rel_error(wa.tau, wb.tau) < tol);
    CHECK(rel_error(wa.tau, wb.Ms * qdd + wb.h - (wb.Q - tau)) < tol);
  }
}

// q̈ of `a` and `b` (the same mechanism on different routes) at random postures (any joint
// types), with M^s q̈ + h = Q on `b`'s equations and τ back from `a`'s inverse dynamics.
void check_same_accelerations(const Model& a, const Model& b, unsigned seed, double tol) {
  Workspace wa(a), wb(b);
  std::mt19937 rng(seed);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 2, rng),
               tau = random_uniform(a.n(), 3, rng);
    REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
    REQUIRE(forward_dynamics(b, wb, q, qd, tau).ok);
    CHECK(rel_error(wa.qdd, wb.qdd) < tol);
    evaluate(b, wb, q, qd, tau);
    CHECK(rel_error(wb.Ms * wa.qdd + wb.h, wb.Q) < tol);
    const VecX qdd = wa.qdd;
    inverse_dynamics(a, wa, q, qd, qdd);
    CHECK(rel_error(wa.tau, tau, wb.Ms.cwiseAbs().maxCoeff() * qdd.cwiseAbs().maxCoeff()) < tol);
  }
}

}  // namespace

TEST_CASE("articulated route equals M^s + Cholesky on mixed random trees", "[routes]") {
  for (unsigned seed = 1; seed <= 6; ++seed)
    for (const int bodies : {1, 2, 5, 12, 30}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const std::string text = mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, false);
      const Model art = load_text(text);
      const Model chol = load_text(
          text, {.routes = {.force = ForceRoute::Nodes, .dynamics = DynamicsRoute::Cholesky}});
      REQUIRE(art.dynamics_route == DynamicsRoute::Articulated);
      REQUIRE(art.force_route == ForceRoute::Bodies);
      check_same_equations(art, chol, seed, 1e-11);
    }
}

TEST_CASE("articulated route equals M^s + Cholesky with joints of several rates", "[routes]") {
  // Universal, planar, spherical and free joints among revolute (springs, dampers), prismatic
  // and fixed ones, point loads and torques, gravity; a free-floating base for odd seeds.
  std::array<int, 8> seen{};
  for (unsigned seed = 1; seed <= 8; ++seed)
    for (const int bodies : {1, 2, 5, 12, 30}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const std::string text = mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, false, true);
      const Model art = load_text(text);
      const Model chol = load_text(
          text, {.routes = {.force = ForceRoute::Nodes, .dynamics = DynamicsRoute::Cholesky}});
      REQUIRE(art.dynamics_route == DynamicsRoute::Articulated);
      for (const Body& b : art.bodies) ++seen[static_cast<int>(b.joint.type)];
      check_same_accelerations(art, chol, seed, 1e-10);
    }
  for (const JointType t : {JointType::Universal, JointType::Planar, JointType::Spherical,
                            JointType::Free, JointType::Revolute, JointType::Fixed})
    CHECK(seen[static_cast<int>(t)] > 3);
}

TEST_CASE("articulated_solve applies (M^s)⁻¹ with joints of several rates", "[routes]") {
  // The factorisation the articulated recursion leaves, applied to random forces, against M^s
  // formed and solved densely; residual M^s x − f checked too.
  for (unsigned seed = 1; seed <= 8; ++seed)
    for (const int bodies : {1, 5, 30}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const std::string text = mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, false, true);
      const Model m = load_text(text);
      REQUIRE(m.dynamics_route == DynamicsRoute::Articulated);
      Workspace ws(m);
      std::mt19937 rng(seed);
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
      REQUIRE(forward_dynamics(m, ws, q, qd, VecX::Zero(m.n())).ok);
      const VecX qdd = ws.qdd;
      Workspace wm(m);
      mass_matrix(m, wm, q);
      for (int k = 0; k < 3; ++k) {
        const VecX f = random_uniform(m.n(), 1, rng);
        VecX x = f;
        articulated_solve(m, ws, x);
        const VecX expected = wm.Ms.ldlt().solve(f);
        CHECK(rel_error(x, expected) < 1e-10);
        CHECK(rel_error(wm.Ms * x, f) < 1e-10);
      }
      CHECK(ws.qdd == qdd);  // the solve leaves the forward dynamics' results alone
    }
}

TEST_CASE("floating-base robots: the articulated route equals M^s + Cholesky", "[routes]") {
  std::vector<std::string> paths;
  for (const char* robot : {"atlas.urdf", "hyq.urdf"})  // (iiwa's root link is the world)
    paths.push_back(std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/" + robot);
  // (hand16's couplings take no free joint: it does not float.)
  for (const char* name : {"urdf/arm7.urdf", "urdf/gantry.urdf"}) paths.push_back(model_path(name));
  for (const std::string& path : paths) {
    INFO(path);
    LoadOptions o;
    o.floating_base = true;
    const Model chosen = load_model(path, o);
    o.compile.routes = {.force = ForceRoute::Nodes, .dynamics = DynamicsRoute::Cholesky};
    const Model reference = load_model(path, o);
    REQUIRE(chosen.bodies[0].joint.type == JointType::Free);
    CHECK(chosen.dynamics_route == DynamicsRoute::Articulated);
    check_same_accelerations(chosen, reference, 7, 1e-10);
  }
}

TEST_CASE("a singular block of several rates fails on the articulated route as on Cholesky",
          "[routes]") {
  // A point mass on a free or spherical joint: its rotation about the line through the joint
  // and the point moves no inertia. Off that line every diagonal entry of M^s is non-zero, so
  // only the block's pivots can tell; compile's check at the reference posture refuses it on
  // either route, naming the same coordinate (the last rate left when the block is eliminated
  // last rate first). A rigid body in its place runs, both routes agreeing.
  for (const char* type : {"free", "spherical"}) {
    for (const bool rigid : {false, true}) {
      INFO(type << (rigid ? ", rigid body" : ", point mass"));
      const std::string element =
          rigid ? R"({"type": "rigid_body", "mass": 1.0, "com": [0.1, 0.2, 0.3],
                      "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.03}})"
                : R"({"type": "lumped_point", "node": [0.1, 0.2, 0.3], "mass": 1.0})";
      const std::string text =
          std::string(R"({"name": "block", "gravity": [0, 0, -9.81], "bodies": [)") +
          R"({"name": "a", "parent": "world", "joint": {"name": "j", "type": ")" + type +
          R"("}, "elements": [)" + element + "]}]}";
      const CompileOptions cholesky{.routes = {.dynamics = DynamicsRoute::Cholesky}};
      if (!rigid) {
        CHECK_THROWS_WITH(load_text(text),
                          Catch::Contains("singular: coordinate 'j.wx' moves no inertia "
                                          "independently of the joints beyond it"));
        CHECK_THROWS_WITH(load_text(text, cholesky),
                          Catch::Contains("singular: coordinate 'j.wx' moves no inertia "
                                          "independently of the coordinates"));
        continue;
      }
      const Model art = load_text(text), chol = load_text(text, cholesky);
      REQUIRE(art.dynamics_route == DynamicsRoute::Articulated);
      check_same_accelerations(art, chol, 2, 1e-10);
    }
  }
}

TEST_CASE("coupled models: Cholesky route, both M^s routes and both force routes agree",
          "[routes]") {
  for (unsigned seed = 11; seed <= 16; ++seed) {
    INFO("seed " << seed);
    const std::string text = mixed_tree_json(seed, 24, 0.5, true);
    const Model composite = load_text(text, {.routes = {.mass = MassRoute::Composite}});
    const Model transform =
        load_text(text, {.routes = {.mass = MassRoute::Transform, .force = ForceRoute::Nodes}});
    REQUIRE(!composite.identity_coupling);
    CHECK(composite.dynamics_route == DynamicsRoute::Cholesky);
    CHECK(composite.force_route == ForceRoute::Bodies);
    check_same_equations(composite, transform, seed, 1e-11);
  }
}

TEST_CASE("articulated route equals the tree LTDL and dense and CHOLMOD Cholesky", "[routes]") {
  // A tree's M^s takes the tree factorisation at every size; dense and CHOLMOD must agree.
  for (const int bodies : {63, 64, 65, 128}) {
    INFO(bodies << " bodies");
    const std::string text = random_tree_json(bodies, bodies, 1.0, true);
    const Model art = load_text(text);
    const Model chol = load_text(
        text, {.routes = {.force = ForceRoute::Nodes, .dynamics = DynamicsRoute::Cholesky}});
    CHECK(Workspace(chol).solver.kind() == SolverKind::Tree);
    check_same_equations(art, chol, bodies, 1e-10);
    Workspace wa(art), wc(chol);
    std::mt19937 rng(bodies);
    const VecX q = random_uniform(art.n(), 2, rng), qd = random_uniform(art.n(), 2, rng),
               tau = random_uniform(art.n(), 3, rng);
    REQUIRE(forward_dynamics(art, wa, q, qd, tau).ok);
    for (const SolverKind kind : {SolverKind::Dense, SolverKind::Sparse}) {
      wc.solver = MassSolver(chol, kind);
      REQUIRE(forward_dynamics(chol, wc, q, qd, tau).ok);
      CHECK(rel_error(wc.qdd, wa.qdd) < 1e-10);
    }
  }
}

TEST_CASE("couplings within a branch keep the tree LTDL and across branches do not", "[routes]") {
  // hand16: each finger's distal joint follows its middle joint (one branch each).
  const Model hand = load_model(model_path("urdf/hand16.urdf"));
  REQUIRE(!hand.identity_coupling);
  CHECK(hand.mass_pattern.solver == SolverKind::Tree);
  // A joint following joints of two branches couples those branches: no tree, no fill-free
  // order, so Dense (or CHOLMOD) is chosen; all three kinds that apply give the same q̈.
  int non_tree = 0;
  for (unsigned seed = 11; seed <= 22; ++seed) {
    INFO("seed " << seed);
    const Model m = load_text(mixed_tree_json(seed, 70, 0.7, true));
    const bool tree = !coordinate_tree(m).empty();
    non_tree += !tree;
    CHECK((m.mass_pattern.solver == SolverKind::Tree) == tree);
    Workspace ws(m);
    std::mt19937 rng(seed);
    const VecX q = random_uniform(m.n(), 2, rng), qd = random_uniform(m.n(), 2, rng),
               tau = random_uniform(m.n(), 3, rng);
    ws.solver = MassSolver(m, SolverKind::Dense);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    const VecX dense = ws.qdd;
    std::vector<SolverKind> kinds = {SolverKind::Sparse};
    if (tree) kinds.push_back(SolverKind::Tree);
    for (const SolverKind kind : kinds) {
      ws.solver = MassSolver(m, kind);
      REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
      CHECK(rel_error(ws.qdd, dense) < 1e-9);
    }
  }
  CHECK(non_tree > 0);  // the sample reaches the cross-branch case
}

TEST_CASE("every bundled and test model: the chosen routes equal the reference routes",
          "[routes]") {
  std::vector<std::string> texts;
  for (const std::string& name : bundled_models()) texts.push_back(model_path(name));
  for (const char* name : {"urdf/arm7.urdf", "urdf/hand16.urdf", "urdf/gantry.urdf"})
    texts.push_back(model_path(name));
  for (const std::string& path : texts) {
    INFO(path);
    const Model chosen = load_model(path);
    const Model reference =
        load_model(path, {.compile = {.routes = {.mass = MassRoute::Transform,
                                                 .force = ForceRoute::Nodes,
                                                 .dynamics = DynamicsRoute::Cholesky}}});
    check_same_equations(chosen, reference, 5, 1e-11);
  }
}

TEST_CASE("chains and trees of 10000 bodies compile and run on the O(n) routes", "[routes]") {
  // Model memory is linear in n (C sparse, no dense T sampled, M^s never formed): the
  // chain's compile and forward dynamics take about a second (docs/performance.md).
  for (const double branching : {0.0, 0.5}) {
    const Model m = load_text(random_tree_json(3, 10000, branching, true));
    REQUIRE(m.n() == 10000);
    CHECK(m.C.nonZeros() == m.n());
    CHECK(m.dynamics_route == DynamicsRoute::Articulated);
    Workspace ws(m);
    CHECK(ws.Ms.size() == 0);
    std::mt19937 rng(5);
    const VecX q = random_uniform(m.n(), 1, rng), qd = random_uniform(m.n(), 1, rng),
               tau = random_uniform(m.n(), 1, rng);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    CHECK(ws.qdd.allFinite());
    // Inverse dynamics of that q̈ gives back τ, to round-off of the forces that balance in it
    // (‖M^s q̈‖ is far larger than ‖τ‖ along 10,000 links: a backward error, not a relative one).
    const VecX qdd = ws.qdd;
    inverse_dynamics(m, ws, q, VecX::Zero(m.n()), qdd);
    const double scale = ws.tau.cwiseAbs().maxCoeff();
    inverse_dynamics(m, ws, q, qd, qdd);
    INFO("scale " << scale);
    CHECK((ws.tau - tau).cwiseAbs().maxCoeff() < 1e-11 * scale);
  }
}

TEST_CASE("energy on the composite route is ½ q̇ᵀ M^s q̇ body by body, M^s never formed",
          "[routes]") {
  for (const bool couplings : {false, true})
    for (const unsigned seed : {3u, 4u}) {
      const Model m = load_text(mixed_tree_json(seed, 25, 0.5, couplings));
      REQUIRE(m.mass_route == MassRoute::Composite);
      std::mt19937 rng(seed);
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
      Workspace ws(m), reference(m);
      const Energy E = energy(m, ws, q, qd);
      CHECK(ws.Ms.size() == 0);  // O(bodies): no n x n matrix
      evaluate(m, reference, q, qd, VecX());
      const double kinetic = 0.5 * qd.dot(reference.Ms * qd);
      INFO("seed " << seed << " couplings " << couplings);
      CHECK(E.kinetic == Approx(kinetic).epsilon(1e-12));
      // The potential is as before: the same body poses.
      const Model transform = load_text(mixed_tree_json(seed, 25, 0.5, couplings),
                                        {.routes = {.mass = MassRoute::Transform}});
      Workspace wt(transform);
      const Energy Et = energy(transform, wt, q, qd);
      CHECK(E.potential == Approx(Et.potential).epsilon(1e-12));
      CHECK(E.kinetic == Approx(Et.kinetic).epsilon(1e-12));
    }
}

TEST_CASE("spanning rods on the body-level routes equal the node-level routes", "[routes]") {
  // Rods across the fixed joints of random trees of every joint type, and the four-bar fingers'
  // trees (every joint a coordinate: their coupler rods join two moving bodies): the composite
  // M^s and Newton–Euler carry the rods as their own terms (core/dynamics/span_inertia.hpp), the
  // reference routes as elements of Tᵀ M T.
  std::vector<std::pair<std::string, std::shared_ptr<const Model>>> cases;
  for (unsigned seed = 31; seed <= 36; ++seed) {
    int rods = 0;
    const std::string text = with_rods(mixed_tree_json(seed, 14, 0.6, false, true), seed, rods);
    if (rods == 0) continue;
    cases.emplace_back(text, nullptr);
  }
  REQUIRE(cases.size() >= 3);
  for (const char* name : {"finger_fourbar.json", "hand_fourbar.json"})
    cases.emplace_back(model_path(name), load_model(model_path(name)).tree);
  const RouteChoice reference_routes{.mass = MassRoute::Transform,
                                     .force = ForceRoute::Nodes,
                                     .dynamics = DynamicsRoute::Cholesky};
  unsigned seed = 40;
  for (const auto& [text, tree] : cases) {
    INFO(text.substr(0, 80));
    const auto owned = [](Model m) { return std::make_shared<const Model>(std::move(m)); };
    const std::shared_ptr<const Model> b = tree ? tree : owned(load_text(text));
    const std::shared_ptr<const Model> r =
        tree ? load_model(text, {.compile = {.routes = reference_routes}}).tree
             : owned(load_text(text, {.routes = reference_routes}));
    const Model &bodies = *b, &reference = *r;
    REQUIRE_FALSE(bodies.condensable);
    CHECK(bodies.mass_route == MassRoute::Composite);
    CHECK(bodies.force_route == ForceRoute::Bodies);
    CHECK(bodies.dynamics_route == DynamicsRoute::Cholesky);
    CHECK_FALSE(bodies.spanning_masses.empty());
    CHECK(reference.spanning_masses.empty());
    check_same_equations(bodies, reference, ++seed, 1e-11);
    // Energy: the rods' ½ Σ ẋ_lᵀ M_lj ẋ_j beside the bodies'.
    std::mt19937 rng(seed);
    const VecX q = random_posture(bodies, rng), qd = random_uniform(bodies.n(), 2, rng);
    Workspace wb(bodies), wr(reference);
    const Energy Eb = energy(bodies, wb, q, qd), Er = energy(reference, wr, q, qd);
    CHECK(Eb.kinetic == Approx(Er.kinetic).epsilon(1e-12));
    CHECK(Eb.potential == Approx(Er.potential).epsilon(1e-12).margin(1e-12));
  }
}

TEST_CASE("coupling laws on the tree's body-level sweeps equal the reference routes", "[routes]") {
  // Random trees with a four-bar, a polynomial and a spline law (core/dynamics/coupling_chain.hpp),
  // joint springs, dampers, friction and rotors on some joints, and rods where a fixed joint
  // allows: forward dynamics by one pair of sweeps with θ̈ = γ as the bias acceleration against the
  // tree's equations formed on the node-level routes and reduced through G.
  const RouteChoice reference_routes{.mass = MassRoute::Transform,
                                     .force = ForceRoute::Nodes,
                                     .dynamics = DynamicsRoute::Cholesky};
  int rods_seen = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    INFO("seed " << seed);
    Json doc = Json::parse(nonlinear_coupled_tree_json(seed));
    for (Json& b : doc["bodies"]) {
      if (b["joint"]["type"] == "fixed") continue;
      const std::string name = b["joint"]["name"];
      if (name == "j1" || name == "j3") b["joint"]["spring"] = {{"stiffness", 2.5}, {"rest", 0.2}};
      if (name == "j0" || name == "j3") b["joint"]["damping"] = 0.4;
      if (name == "j1") b["joint"]["friction"] = 0.3;
      if (name == "j0" || name == "j5") b["joint"]["armature"] = 0.05;
    }
    for (const char* parent : {"b2", "b4"})  // a welded tip, for a rod across its fixed joint
      doc["bodies"].push_back(
          {{"name", std::string(parent) + "_tip"},
           {"parent", parent},
           {"joint", {{"name", std::string(parent) + "_weld"}, {"type", "fixed"}}},
           {"nodes", {{"tip", {0.1, 0, 0.05}}}},
           {"elements", {{{"type", "lumped_point"}, {"mass", 0.2}, {"node", "tip"}}}}});
    int rods = 0;
    const std::string text = with_rods(doc.dump(), seed, rods);
    rods_seen += rods;
    const Model chosen = load_text(text);
    const Model reference = load_text(text, {.routes = reference_routes});
    REQUIRE(chosen.coupling_level);
    CHECK(chosen.tree->force_route == ForceRoute::Bodies);
    CHECK(chosen.tree->mass_route == MassRoute::Composite);
    CHECK(reference.tree->force_route == ForceRoute::Nodes);
    check_same_equations(chosen, reference, seed, 1e-11);
    // h alone (evaluate_bias: the tree's Newton–Euler at θ̈ = γ) against the reference's h.
    Workspace wc(chosen), wr(reference);
    std::mt19937 rng(seed);
    const VecX q = random_posture(chosen, rng), qd = random_uniform(chosen.n(), 2, rng);
    evaluate_bias(chosen, wc, q, qd);
    evaluate(reference, wr, q, qd, VecX::Zero(chosen.n()));
    CHECK(rel_error(wc.h, wr.h, wr.Ms.cwiseAbs().maxCoeff() * qd.squaredNorm()) < 1e-11);
  }
  CHECK(rods_seen > 0);
}

TEST_CASE("the routes' names say which function the table calls", "[routes]") {
  // Each name is set where the route is chosen: a model asked for a route reports that route,
  // and the names tell the body level from the reference, and loops from none.
  const std::string text = mixed_tree_json(3, 7, 0.4, false, true);
  const Model body_level = load_text(text);
  const Model reference = load_text(text, {.routes = {.mass = MassRoute::Transform,
                                                      .force = ForceRoute::Nodes,
                                                      .dynamics = DynamicsRoute::Cholesky}});
  REQUIRE(body_level.routes.forward_dynamics == &articulated_forward_dynamics);
  const RouteReport a = route_report(body_level), b = route_report(reference);
  CHECK(a.mass == "composite body inertias");
  CHECK(a.force == "recursive Newton–Euler over the bodies");
  CHECK(a.forward == "articulated bodies");
  CHECK(a.solver.empty());  // (no factorisation of M^s on the articulated route)
  CHECK(b.mass == "Tᵀ M T (the transform T)");
  CHECK(b.force == "node sweeps (Tᵀ, T')");
  CHECK(b.forward == "the equations, then Cholesky");
  CHECK_FALSE(b.solver.empty());
  CHECK(a.loops.empty());
  // A coupling law: the chain's names; closed loops: the constrained q̈ named.
  CHECK_THAT(route_report(load_model(model_path("finger_fourbar.json"))).mass,
             Catch::Contains("coupling law"));
  const RouteReport loops = route_report(load_model(model_path("five_bar.json")));
  CHECK_THAT(loops.loops, Catch::Contains("Φ_q q̈ = −Φ̇_q q̇"));
  CHECK(loops.fields().size() == 4);  // mass, force, forward_dynamics (articulated), loops
}
