// Forward and inverse dynamics; CHOLMOD against dense Cholesky on a large sparse tree.
#include <algorithm>
#include <catch2/catch.hpp>

#include "core/workspace/mass_pattern.hpp"
#include "core/workspace/mass_solver.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

TEST_CASE("inverse dynamics inverts forward dynamics", "[solver]") {
  const Model m = load_text(random_tree_json(31, 10, 0.5, true));
  Workspace ws(m);
  std::mt19937 rng(31);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(m.n(), 2, rng), qd = random_uniform(m.n(), 2, rng),
               tau = random_uniform(m.n(), 3, rng);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    const VecX qdd = ws.qdd;
    evaluate(m, ws, q, qd, tau);
    CHECK(rel_error(ws.Ms * qdd + ws.h, ws.Q) < 1e-12);
    inverse_dynamics(m, ws, q, qd, qdd);
    CHECK(rel_error(ws.tau, tau) < 1e-10);
  }
}

TEST_CASE("tree LTDL and CHOLMOD and dense Cholesky agree on a 90-DOF bushy tree", "[solver]") {
  const Model m = load_text(random_tree_json(41, 90, 1.0, true));
  REQUIRE(m.n() == 90);
  INFO("fill " << mass_matrix_fill(m));
  CHECK(m.mass_pattern.solver == SolverKind::Tree);
  MassSolver dense(m, SolverKind::Dense), sparse(m, SolverKind::Sparse), tree(m, SolverKind::Tree);
  Workspace ws(m);
  std::mt19937 rng(41);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_uniform(m.n(), 2, rng), y = random_uniform(m.n(), 1, rng);
    evaluate(m, ws, q, VecX::Zero(m.n()), VecX());
    REQUIRE(dense.factorize(ws.Ms).ok);
    REQUIRE(sparse.factorize(ws.Ms).ok);
    REQUIRE(tree.factorize(ws.Ms).ok);
    VecX xd, xs, xt;
    dense.solve(y, xd);
    sparse.solve(y, xs);
    tree.solve(y, xt);
    CHECK(rel_error(ws.Ms * xs, y) < 1e-10);
    CHECK(rel_error(ws.Ms * xt, y) < 1e-10);
    CHECK(rel_error(xs, xd) < 1e-8);
    CHECK(rel_error(xt, xd) < 1e-8);
  }
  // A chain's coordinate tree is the chain itself: λ(a) = a − 1.
  const std::vector<int> chain = coordinate_tree(load_text(random_tree_json(42, 4, 0.0, false)));
  CHECK(chain == std::vector<int>{-1, 0, 1, 2});
}

TEST_CASE("the tree LTDL names the coordinate whose pivot is lost", "[solver]") {
  // M^s of a 3-coordinate chain made singular by hand: coordinate 2 (the leaf) copies
  // coordinate 1, so eliminating the leaf first leaves no pivot for coordinate 1.
  const Model m = load_text(random_tree_json(42, 3, 0.0, false));
  MassSolver tree(m, SolverKind::Tree);
  MatX Ms(3, 3);
  Ms << 4, 1, 1,  //
      1, 2, 2,    //
      1, 2, 2;
  const Status st = tree.factorize(Ms);
  CHECK(!st.ok);
  CHECK(st.coordinate == 1);
  CHECK_THAT(st.message, Catch::Contains("coordinate '" + m.coordinate_names[1] +
                                         "' moves no inertia independently"));
  // A positive definite matrix is solved exactly.
  Ms(2, 2) = 3;
  REQUIRE(tree.factorize(Ms).ok);
  VecX x;
  tree.solve(VecX::Ones(3), x);
  CHECK(rel_error(Ms * x, VecX::Ones(3)) < 1e-14);
}

TEST_CASE("the structural pattern of M^s holds: different branches decouple exactly", "[solver]") {
  const Model m = load_text(random_tree_json(43, 20, 1.0, false));
  Workspace ws(m);
  std::mt19937 rng(43);
  evaluate(m, ws, random_uniform(m.n(), 2, rng), VecX::Zero(m.n()), VecX());
  int zeros = 0;
  for (int a = 0; a < m.n(); ++a)
    for (int b = 0; b < m.n(); ++b) zeros += ws.Ms(a, b) == 0.0;
  const double fill = mass_matrix_fill(m);
  CHECK(zeros == static_cast<int>(std::lround((1 - fill) * m.n() * m.n())));
}

TEST_CASE("O(n) inverse dynamics and bias (Tᵀ by a backward sweep) equal the matrix forms",
          "[solver]") {
  // Every bundled model (the paper's finger has aliased DOFs and an explicit table), every
  // URDF robot, and random trees with couplings, loads, springs and dampers.
  std::vector<std::string> paths;
  for (const std::string& name : bundled_models()) paths.push_back(model_path(name));
  for (const char* name : {"urdf/arm7.urdf", "urdf/hand16.urdf", "urdf/gantry.urdf"})
    paths.push_back(model_path(name));
  std::vector<Model> models;
  for (const auto& p : paths) models.push_back(load_model(p));
  for (unsigned seed = 1; seed <= 4; ++seed)
    models.push_back(load_text(random_tree_json(seed, 12, 0.5, true)));
  models.push_back(load_text(R"({"name": "loaded", "gravity": [0.5, -1, -9.81], "bodies": [
    {"name": "a", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 0, 1],
     "damping": 0.3}, "elements": [{"type": "rigid_body", "mass": 1, "com": [0.2, 0.01, 0],
     "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.025}}]},
    {"name": "b", "parent": "a", "joint": {"name": "j2", "type": "prismatic", "axis": [1, 0.3, 0],
     "origin": {"xyz": [0.4, 0, 0]}, "spring": {"stiffness": 40, "rest": 0.05}},
     "elements": [{"type": "rigid_body", "mass": 0.7, "com": [0.15, 0, 0.02],
                   "inertia": {"ixx": 0.004, "iyy": 0.01, "izz": 0.012, "ixy": 0.001}}]},
    {"name": "c", "parent": "b", "joint": {"name": "j3", "type": "revolute", "axis": [0, 1, 0.3],
     "origin": {"xyz": [0.3, 0, 0], "rpy": [0.2, 0.1, -0.4]}},
     "elements": [{"type": "space_bar", "nodes": [[0, 0, 0], [0.2, 0.01, 0]], "density": 2700,
                   "area": 1e-4, "Iy": 1e-9, "Iz": 2e-9}]}],
    "couplings": [{"joint": "j3", "follows": [{"joint": "j1", "ratio": 0.5},
                                              {"joint": "j2", "ratio": 2}], "offset": 0.1}],
    "loads": [{"body": "c", "point": [0.1, 0, 0], "force": [1, 2, 3], "torque": [0.3, -0.1, 0.2]},
              {"body": "b", "point": [0, 0.1, 0], "torque": [0, 0, 0.5]}]})"));
  std::mt19937 rng(9);
  for (const Model& m : models) {
    INFO(m.name);
    Workspace ws(m);
    for (int k = 0; k < 3; ++k) {
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2.0, rng),
                 qdd = random_uniform(m.n(), 3.0, rng);
      evaluate(m, ws, q, qd, VecX());
      const VecX h = ws.h, Q = ws.Q, expected = ws.Ms * qdd + ws.h - ws.Q;
      evaluate_bias(m, ws, q, qd);
      CHECK(rel_error(ws.h, h) < 1e-13);
      inverse_dynamics(m, ws, q, qd, qdd);
      CHECK(rel_error(ws.tau, expected) < 1e-13);
    }
  }
}

TEST_CASE("M^s by composite inertias (composite route) equals Tᵀ M T", "[solver]") {
  std::vector<Model> models;
  for (const std::string& name : bundled_models()) models.push_back(load_model(model_path(name)));
  for (const char* name : {"urdf/arm7.urdf", "urdf/hand16.urdf", "urdf/gantry.urdf"})
    models.push_back(load_model(model_path(name)));
  for (unsigned seed = 1; seed <= 4; ++seed)
    models.push_back(load_text(random_tree_json(seed, 15, 0.5, true)));
  std::mt19937 rng(12);
  int condensed = 0;
  for (const Model& m : models) {
    INFO(m.name);
    // Automatic tables with physical elements condense; the paper's explicit table does not,
    // nor a model with an element spanning two bodies (a four-bar's coupler rod).
    const bool spans = std::any_of(m.elements.begin(), m.elements.end(),
                                   [](const ElementEntry& e) { return e.spans; });
    CHECK(m.condensable == (!m.explicit_table && !spans));
    // The composite route wherever it is exact (compile's choice), or exact but for spanning
    // rods that it then carries as their own terms (core/dynamics/span_inertia.hpp).
    CHECK((m.mass_route == MassRoute::Composite) == (m.condensable || !m.spanning_masses.empty()));
    CHECK(m.spanning_masses.empty() == !spans);
    condensed += m.mass_route == MassRoute::Composite;
    Workspace ws(m);
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 1.0, rng);
    evaluate(m, ws, q, qd, VecX());
    const MatX Ms = ws.Ms;
    propagate(m, ws, q, qd, {.jacobian = true, .bias = false});  // forms T
    const MatX dense = ws.T.transpose() * (m.M * ws.T);
    CHECK(rel_error(Ms, dense) < 1e-13);
  }
  CHECK(condensed >= 5);  // chosen where it is cheaper: the hands, arms, larger trees
}
