// Forward and inverse dynamics; CHOLMOD against dense Cholesky on a large sparse tree.
#include <catch2/catch.hpp>

#include "core/mass_solver.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

TEST_CASE("inverse dynamics inverts forward dynamics", "[solver]") {
  const Model m = load_text(random_tree_json(31, 10, 0.5, true));
  Workspace ws(m);
  std::mt19937 rng(31);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_vector(rng, m.n(), 2), qd = random_vector(rng, m.n(), 2),
               tau = random_vector(rng, m.n(), 3);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    const VecX qdd = ws.qdd;
    CHECK(rel_error(ws.Ms * qdd + ws.h, ws.Q) < 1e-12);
    inverse_dynamics(m, ws, q, qd, qdd);
    CHECK(rel_error(ws.tau, tau) < 1e-10);
  }
}

TEST_CASE("CHOLMOD and dense Cholesky agree on a 90-DOF bushy tree", "[solver]") {
  const Model m = load_text(random_tree_json(41, 90, 1.0, true));
  REQUIRE(m.n() == 90);
  INFO("fill " << mass_matrix_fill(m));
  CHECK(choose_solver(m) == SolverKind::Sparse);
  MassSolver dense(m, SolverKind::Dense), sparse(m, SolverKind::Sparse);
  Workspace ws(m);
  std::mt19937 rng(41);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_vector(rng, m.n(), 2), y = random_vector(rng, m.n(), 1);
    evaluate(m, ws, q, VecX::Zero(m.n()), VecX());
    REQUIRE(dense.factorize(ws.Ms).ok);
    REQUIRE(sparse.factorize(ws.Ms).ok);
    VecX xd, xs;
    dense.solve(y, xd);
    sparse.solve(y, xs);
    CHECK(rel_error(ws.Ms * xs, y) < 1e-10);
    CHECK(rel_error(xs, xd) < 1e-8);
  }
  // A small chain stays dense: no sparse machinery for a few DOFs.
  CHECK(choose_solver(load_text(random_tree_json(42, 4, 0.0, false))) == SolverKind::Dense);
}

TEST_CASE("the structural pattern of M^s holds: different branches decouple exactly", "[solver]") {
  const Model m = load_text(random_tree_json(43, 20, 1.0, false));
  Workspace ws(m);
  std::mt19937 rng(43);
  evaluate(m, ws, random_vector(rng, m.n(), 2), VecX::Zero(m.n()), VecX());
  int zeros = 0;
  for (int a = 0; a < m.n(); ++a)
    for (int b = 0; b < m.n(); ++b) zeros += ws.Ms(a, b) == 0.0;
  const double fill = mass_matrix_fill(m);
  CHECK(zeros == static_cast<int>(std::lround((1 - fill) * m.n() * m.n())));
}
