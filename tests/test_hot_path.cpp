// The hot path allocates nothing: evaluate / forward / inverse dynamics on a warm workspace.
// Counted by interposing malloc in this test binary (glibc); skipped under sanitizers (ASan owns
// malloc there: tools/sanitize.sh).
#include <catch2/catch.hpp>
#include <cstdlib>

#include "core/integrator.hpp"
#include "tests/helpers.hpp"

namespace {
thread_local bool g_counting = false;
thread_local long g_mallocs = 0;
}  // namespace
#ifdef FEMDYN_SANITIZED
// Under ASan (tools/sanitize.sh) malloc is the sanitizer's: an interposer would take its place
// (ASan aborts at start-up) and nothing here could be counted. Each test says so and returns;
// ctest reports it as Skipped (SKIP_REGULAR_EXPRESSION in tests/CMakeLists.txt).
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
extern "C" void* __libc_malloc(std::size_t);
extern "C" void* malloc(std::size_t n) {
  if (g_counting) ++g_mallocs;
  return __libc_malloc(n);
}
#endif
constexpr const char* kSkipped = "skipped under sanitizers: ASan owns malloc, nothing is counted";

using namespace femdyn;
using namespace femdyn::test;

TEST_CASE("no heap allocation in evaluate, forward and inverse dynamics",
          "[hot-path]") {
  if (kSanitized) {
    WARN(kSkipped);
    return;
  }
  for (const char* name : {"branched_tree.json", "spatial_double_pendulum.json", "hand.json",
                           "finger_coupled.json", "finger_paper.json", "urdf/hand16.urdf"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    Workspace ws(m);
    std::mt19937 rng(3);
    const VecX q = random_vector(rng, m.n(), 1), qd = random_vector(rng, m.n(), 1),
               tau = random_vector(rng, m.n(), 1), qdd = random_vector(rng, m.n(), 1);
    // Warm-up: buffers a route needs are sized on its first call.
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    evaluate(m, ws, q, qd, tau);
    inverse_dynamics(m, ws, q, qd, qdd);
    g_mallocs = 0;
    g_counting = true;
    evaluate(m, ws, q, qd, tau);
    const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
    inverse_dynamics(m, ws, q, qd, qdd);
    evaluate_bias(m, ws, q, qd);
    g_counting = false;
    CHECK(ok);
    CHECK(g_mallocs == 0);
  }
}

TEST_CASE("no heap allocation per step after the first, for every integrator", "[hot-path]") {
  if (kSanitized) {
    WARN(kSkipped);
    return;
  }
  for (const char* name : {"branched_tree.json", "hand.json", "urdf/hand16.urdf"}) {
    const Model m = load_model(model_path(name));
    std::mt19937 rng(5);
    const VecX q = random_vector(rng, m.n(), 0.5), qd = random_vector(rng, m.n(), 0.5),
               tau = random_vector(rng, m.n(), 0.1);
    for (IntegratorKind kind : kIntegrators) {
      INFO(name << " " << integrator_name(kind));
      IntegratorOptions o{.kind = kind, .fixed = {.dt = 1e-4}, .adaptive = {.rtol = 1e-8}};
      auto integ = make_integrator(m, o, [&tau](double, VecX& out) { out = tau; });
      integ->reset(0, q, qd, 1.0);
      for (int k = 0; k < 5; ++k) REQUIRE(integ->step().ok);  // warm-up
      g_mallocs = 0;
      g_counting = true;
      bool ok = true;
      for (int k = 0; k < 20; ++k) ok = ok && integ->step().ok;
      g_counting = false;
      CHECK(ok);
      CHECK(g_mallocs == 0);
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
  if (kSanitized) {
    WARN(kSkipped);
    return;
  }
  for (int bodies : {70, 140}) {
    Model m = load_text(random_tree_json(4, bodies, 0.5, true));
    m.dynamics_route = DynamicsRoute::Cholesky;  // (compile chooses the articulated route)
    Workspace ws(m);
    ws.solver = MassSolver(m, SolverKind::Sparse);  // (a tree would take the tree LTDL)
    std::mt19937 rng(3);
    const VecX q = random_vector(rng, m.n(), 1), qd = random_vector(rng, m.n(), 1),
               tau = random_vector(rng, m.n(), 1);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    g_mallocs = 0;
    g_counting = true;
    const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
    g_counting = false;
    CHECK(ok);
    CHECK(g_mallocs <= 4);  // independent of the size
  }
}
