// femdyn's equations of a URDF against the independent URDF twin (validation/urdf_twin.hpp),
// shared by the URDF tests. Only with Simbody.
#pragma once
#ifdef FEMDYN_WITH_SIMBODY
#include <catch2/catch.hpp>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "tests/helpers.hpp"
#include "validation/urdf_twin.hpp"

namespace femdyn::test {

// M^s, h and Q of `m` equal the twin's within `tol` (relative) at `states` states: q = draw_q(),
// q̇ uniform in ±2.
template <class DrawQ>
void check_equal_to_twin(const Model& m, validation::UrdfTwin& twin, std::mt19937& rng,
                         DrawQ draw_q, double tol = 1e-10, int states = 4) {
  Workspace ws(m);
  for (int k = 0; k < states; ++k) {
    const VecX q = draw_q(), qd = random_uniform(m.n(), 2.0, rng);
    evaluate(m, ws, q, qd, VecX());
    const validation::UrdfTwinEquations s =
        twin.equations(m.coordinate_names, m.configuration_names, q, qd);
    CHECK(rel_error(ws.Ms, s.M) < tol);
    CHECK(rel_error(ws.h, s.h) < tol);
    CHECK(rel_error(ws.Q, s.Q) < tol);
  }
}

}  // namespace femdyn::test
#endif
