// Checks shared by the tests against Simbody (test_validation.cpp, test_mobilizers.cpp).
#pragma once
#include <catch2/catch.hpp>
#include <string>

#include "validation/validate.hpp"

namespace femdyn::test {

inline validation::ValidationOptions quick(int states = 8, double t_end = 0.1) {
  validation::ValidationOptions o;
  o.states = states;
  o.t_end = t_end;
#ifdef FEMDYN_SANITIZED
  // The budget guards a user's wall clock; these checks are about agreement. Under ASan + UBSan
  // the work runs several times slower (Andrews' whole validation is estimated at 2.1 min there,
  // 22 s in Release), and with the other test of ctest -j2 beside it crossed the default 120 s.
  o.budget *= 5;
#endif
  return o;
}

// Every quantity within 1e-10 relative, and the trajectory run, resolved and within tolerance.
inline void require_pass(const validation::ValidationReport& r, const std::string& label) {
  INFO(label << (r.failure.empty() ? "" : ": " + r.failure));
  REQUIRE(r.failure.empty());
  for (const auto& q : r.quantities) {
    INFO(q.name << " max rel error " << q.max_rel);
    CHECK(q.max_rel < 1e-10);
  }
  INFO("trajectory: " << r.trajectory.skipped << r.trajectory.stopped << " error "
                      << r.trajectory.max_state_error << " tolerance " << r.trajectory.tolerance);
  CHECK(r.trajectory.run);
  CHECK(r.trajectory.resolved);
  CHECK(r.trajectory.max_state_error <= r.trajectory.tolerance);
  CHECK(r.pass());
}

}  // namespace femdyn::test
