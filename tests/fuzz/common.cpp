#include "tests/fuzz/common.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <typeinfo>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"

#ifndef FEMDYN_FUZZ_NAN_CHECK
#define FEMDYN_FUZZ_NAN_CHECK 1
#endif

namespace femdyn::fuzz {

bool nan_check() {
  static const bool on = [] {
    const char* env = std::getenv("FEMDYN_FUZZ_NAN_CHECK");
    if (env && *env) return std::strcmp(env, "0") != 0;
    return FEMDYN_FUZZ_NAN_CHECK != 0;
  }();
  return on;
}

void bug(const std::string& what) {
  std::fprintf(stderr, "femdyn fuzz: BUG: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

void note(const std::string& what) {
  static const bool verbose = [] {
    const char* env = std::getenv("FEMDYN_FUZZ_VERBOSE");
    return env && *env && std::strcmp(env, "0") != 0;
  }();
  if (verbose) std::fprintf(stderr, "femdyn fuzz: %s\n", what.c_str());
}

void check_message(const char* stage, const std::string& what) {
  if (!printable_text(what))
    bug(std::string(stage) +
        ": the error message holds a control character or a byte that is "
        "not UTF-8 (shown escaped): " +
        escaped(what));
}

std::uint64_t hash(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  return h;
}

bool all_finite(const Json& j) {
  if (j.is_number_float()) return std::isfinite(j.get<double>());
  if (j.is_structured())
    for (const Json& x : j)
      if (!all_finite(x)) return false;
  return true;
}

namespace {

// splitmix64: the same sequence with every compiler and standard library.
double uniform(std::uint64_t& s) {  // in [-1, 1]
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}

const char* first_non_finite(const MatX& Ms, const VecX& h, const VecX& Q, const VecX& qdd) {
  if (!Ms.allFinite()) return "M^s";
  if (!h.allFinite()) return "h";
  if (!Q.allFinite()) return "Q";
  if (!qdd.allFinite()) return "q̈";
  return nullptr;
}

}  // namespace

void evaluate_once(const Model& model, std::uint64_t seed, bool inputs_finite) {
  const int n = model.n();
  VecX q(n), qd(n), tau(n);
  for (int i = 0; i < n; ++i) {
    q[i] = 0.5 * uniform(seed);
    qd[i] = uniform(seed);
    tau[i] = uniform(seed);
  }
  if (model.n_q() != n) {  // a quaternion: q has n_q entries, each quaternion of norm 1
    std::mt19937 rng(static_cast<std::mt19937::result_type>(seed));
    q = random_posture(model, rng);
  }
  Workspace ws(model);
  const Status st = forward_dynamics(model, ws, q, qd, tau);
  const VecX qdd = ws.qdd;
  evaluate(model, ws, q, qd, tau);
  note("evaluated " + std::to_string(n) + " coordinates: forward_dynamics " +
       (st.ok ? std::string("ok") : "failed: " + st.message));
  if (!st.ok || !inputs_finite || !nan_check()) return;
  if (const char* what = first_non_finite(ws.Ms, ws.h, ws.Q, qdd))
    bug(std::string(what) + " has NaN or Inf, forward_dynamics returned ok, every input finite");
}

}  // namespace femdyn::fuzz
