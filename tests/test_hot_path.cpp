// The hot path allocates nothing: evaluate / forward / inverse dynamics on a warm workspace.
// Counted by interposing malloc (validation/alloc_counter.hpp); skipped under sanitizers (ASan
// owns malloc there: tools/sanitize.sh), which ctest reports as Skipped
// (SKIP_REGULAR_EXPRESSION in tests/CMakeLists.txt).
#include <catch2/catch.hpp>
#include <cstdlib>

#include "core/derivatives/derivatives.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "tests/loop_checks.hpp"
#include "validation/alloc_counter.hpp"

using femdyn::alloc_counter::kAvailable;
constexpr const char* kSkipped = "skipped under sanitizers: ASan owns malloc, nothing is counted";

using namespace femdyn;
using namespace femdyn::test;

TEST_CASE("no heap allocation in evaluate, forward and inverse dynamics", "[hot-path]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  for (const char* name :
       {"branched_tree.json", "spatial_double_pendulum.json", "hand.json", "finger_coupled.json",
        "finger_paper.json", "finger_fourbar.json", "hand_fourbar.json", "urdf/hand16.urdf"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    Workspace ws(m);
    std::mt19937 rng(3);
    const VecX q = random_uniform(m.n(), 1, rng), qd = random_uniform(m.n(), 1, rng),
               tau = random_uniform(m.n(), 1, rng), qdd = random_uniform(m.n(), 1, rng);
    // Warm-up: buffers a route needs are sized on its first call.
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    evaluate(m, ws, q, qd, tau);
    inverse_dynamics(m, ws, q, qd, qdd);
    alloc_counter::start();
    evaluate(m, ws, q, qd, tau);
    const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
    inverse_dynamics(m, ws, q, qd, qdd);
    evaluate_bias(m, ws, q, qd);
    const long mallocs = alloc_counter::stop();
    CHECK(ok);
    CHECK(mallocs == 0);
  }
}

TEST_CASE("no heap allocation in the analytic derivatives after the first call", "[hot-path]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  // Trees, a free base, linear couplings, two-point springs, coupling laws (over a tree with
  // spanning rods).
  for (const char* name : {"hand.json", "space_robot.json", "finger_coupled.json",
                           "iftomm_a05_flyball.json", "finger_fourbar.json", "hand_fourbar.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    Workspace ws(m);
    DerivativeWorkspace d(m);
    std::mt19937 rng(3);
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 1, rng),
               tau = random_uniform(m.n(), 1e-3, rng), qdd = random_uniform(m.n(), 1, rng);
    REQUIRE(forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok);  // warm-up
    inverse_dynamics_derivatives(m, ws, d, q, qd, qdd);
    alloc_counter::start();
    const bool ok = forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok;
    inverse_dynamics_derivatives(m, ws, d, q, qd, qdd);
    const long mallocs = alloc_counter::stop();
    CHECK(ok);
    CHECK(mallocs == 0);
  }
}

TEST_CASE("no heap allocation in the closed loops' derivatives after the first call",
          "[hot-path][loop_derivatives]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  // Balls (redundant on Bricard's), point on line, distances; a weld, a distance and a gear on a
  // random tree.
  const Model random = load_text(closable_tree(2, true));
  for (const char* name : {"five_bar.json", "delta.json", "iftomm_a04_bricard.json", ""}) {
    INFO(name);
    const Model loaded = *name ? load_model(model_path(name)) : Model{};
    const Model& m = *name ? loaded : random;
    Workspace ws(m);
    DerivativeWorkspace d(m);
    std::mt19937 rng(3);
    VecX q = neutral_posture(m), qd = random_uniform(m.n(), 1, rng);
    const VecX tau = random_uniform(m.n(), 1e-3, rng);
    REQUIRE(assemble_state(m, q, qd).assembly.status.ok);
    REQUIRE(forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok);  // warm-up
    alloc_counter::start();
    const bool ok = forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok;
    const long mallocs = alloc_counter::stop();
    CHECK(ok);
    CHECK(mallocs == 0);
  }
}

TEST_CASE("no heap allocation in the articulated route over joints of several rates",
          "[hot-path]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  // A floating base (free joint, 6 rates) carrying a tree of revolute joints.
  LoadOptions o;
  o.floating_base = true;
  const Model m = load_model(std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/atlas.urdf", o);
  REQUIRE(m.dynamics_route == DynamicsRoute::Articulated);
  REQUIRE(m.bodies[0].joint.nv == 6);
  Workspace ws(m);
  std::mt19937 rng(3);
  const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 1, rng),
             tau = random_uniform(m.n(), 1, rng);
  REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);  // warm-up
  alloc_counter::start();
  const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
  const long mallocs = alloc_counter::stop();
  CHECK(ok);
  CHECK(mallocs == 0);
}

TEST_CASE("no heap allocation per step after the first, for every integrator", "[hot-path]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  for (const char* name : {"branched_tree.json", "hand.json", "urdf/hand16.urdf"}) {
    const Model m = load_model(model_path(name));
    std::mt19937 rng(5);
    const VecX q = random_uniform(m.n(), 0.5, rng), qd = random_uniform(m.n(), 0.5, rng),
               tau = random_uniform(m.n(), 0.1, rng);
    for (IntegratorKind kind : kIntegrators) {
      INFO(name << " " << integrator_name(kind));
      IntegratorOptions o{.kind = kind, .fixed = {.dt = 1e-4}, .adaptive = {.rtol = 1e-8}};
      auto integ = make_integrator(m, o, [&tau](double, VecX& out) { out = tau; });
      integ->reset(0, q, qd, 1.0);
      for (int k = 0; k < 5; ++k) REQUIRE(integ->step().ok);  // warm-up
      alloc_counter::start();
      bool ok = true;
      for (int k = 0; k < 20; ++k) ok = ok && integ->step().ok;
      const long mallocs = alloc_counter::stop();
      CHECK(ok);
      CHECK(mallocs == 0);
    }
  }
}

// Known limit: CHOLMOD's numeric factorisation allocates three small work arrays per call
// internally, and cholmod_solve2 one (every buffer femdyn owns is reused: the matrix, its
// ordering, the factor, the solve's X, Y, E). The sparse path is chosen only from 64 DOF up;
// every smaller model takes the dense path above, which allocates nothing. This test pins the
// count so that a regression shows.
TEST_CASE("the sparse (CHOLMOD) path allocates only CHOLMOD's own few work arrays per call",
          "[hot-path]") {
  if (!kAvailable) {
    WARN(kSkipped);
    return;
  }
  for (int bodies : {70, 140}) {
    // (compile would choose the articulated route)
    const Model m = load_text(random_tree_json(4, bodies, 0.5, true),
                              {.routes = {.dynamics = DynamicsRoute::Cholesky}});
    Workspace ws(m);
    ws.solver = MassSolver(m, SolverKind::Sparse);  // (a tree would take the tree LTDL)
    std::mt19937 rng(3);
    const VecX q = random_uniform(m.n(), 1, rng), qd = random_uniform(m.n(), 1, rng),
               tau = random_uniform(m.n(), 1, rng);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    alloc_counter::start();
    const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
    const long mallocs = alloc_counter::stop();
    CHECK(ok);
    CHECK(mallocs <= 4);  // independent of the size
  }
}
