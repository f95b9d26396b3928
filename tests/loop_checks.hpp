// The equations a closed mechanism's q̈ and λ must satisfy at a consistent state (q, v):
// Φ_q v = 0 (the state is on the loops), Φ_q q̈ + Φ̇_q v = 0, and M q̈ + h = Q(τ) + Φ_qᵀ λ
// (inverse dynamics of q̈ gives back τ + Φ_qᵀ λ). Returns the constraints' rank at the solve.
#pragma once
#include <catch2/catch.hpp>

#include "core/equations.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "tests/helpers.hpp"

namespace femdyn::test {

inline int check_constrained_equations(const Model& m, const VecX& q, const VecX& v,
                                       const VecX& tau) {
  Workspace ws(m);
  LoopWorkspace lws(m);
  constraint_kinematics(m, ws, q, v, lws.k);
  CHECK((lws.k.J * v).cwiseAbs().maxCoeff() < 1e-12);
  REQUIRE(constrained_forward_dynamics(m, ws, lws, q, v, tau, 0).ok);
  const int rank = lws.rank;
  const VecX qdd = ws.qdd, lambda = lws.lambda;
  constraint_kinematics(m, ws, q, v, lws.k);
  const VecX accel = lws.k.J * qdd + lws.k.bias;
  CHECK(accel.cwiseAbs().maxCoeff() < 1e-9 * (1 + (lws.k.J * qdd).cwiseAbs().maxCoeff()));
  inverse_dynamics(m, ws, q, v, qdd);
  const VecX expected = tau + lws.k.J.transpose() * lambda;
  CHECK(rel_error(ws.tau, expected, 1e-6) < 1e-10);
  return rank;
}

}  // namespace femdyn::test
