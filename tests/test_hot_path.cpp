// The hot path allocates nothing: evaluate / forward / inverse dynamics on a warm workspace.
// Counted by interposing malloc in this test binary (glibc).
#include <catch2/catch.hpp>
#include <cstdlib>

#include "tests/helpers.hpp"

extern "C" void* __libc_malloc(std::size_t);
namespace {
thread_local bool g_counting = false;
thread_local long g_mallocs = 0;
}  // namespace
extern "C" void* malloc(std::size_t n) {
  if (g_counting) ++g_mallocs;
  return __libc_malloc(n);
}

using namespace femdyn;
using namespace femdyn::test;

TEST_CASE("no heap allocation in evaluate, forward and inverse dynamics", "[hot-path]") {
  for (const char* name : {"branched_tree.json", "spatial_double_pendulum.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    Workspace ws(m);
    std::mt19937 rng(3);
    const VecX q = random_vector(rng, m.n(), 1), qd = random_vector(rng, m.n(), 1),
               tau = random_vector(rng, m.n(), 1), qdd = random_vector(rng, m.n(), 1);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);  // warm-up
    inverse_dynamics(m, ws, q, qd, qdd);
    g_mallocs = 0;
    g_counting = true;
    evaluate(m, ws, q, qd, tau);
    const bool ok = forward_dynamics(m, ws, q, qd, tau).ok;
    inverse_dynamics(m, ws, q, qd, qdd);
    g_counting = false;
    CHECK(ok);
    CHECK(g_mallocs == 0);
  }
}
