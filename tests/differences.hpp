// Numerical derivatives for the analytic derivatives' tests (tests/test_derivatives.cpp,
// tests/test_loop_derivatives.cpp): central differences along the tangent q ⊕ ε e_m of
// integrate_posture (core/kinematics/sampling.hpp) or along v + ε e_m, and their Richardson
// extrapolation.
#pragma once
#include <functional>

#include "core/kinematics/sampling.hpp"
#include "core/model/model.hpp"

namespace femdyn::test {

using Function = std::function<VecX(const VecX& q, const VecX& v)>;

// Central difference with step h along q ⊕ ε e_m (wrt_q) or v + ε e_m.
inline MatX central(const Model& m, const Function& f, const VecX& q, const VecX& v, bool wrt_q,
                    double h) {
  const int n = m.n();
  MatX J(n, n);
  for (int k = 0; k < n; ++k) {
    const VecX e = VecX::Unit(n, k);
    const VecX plus = wrt_q ? f(integrate_posture(m, q, h * e), v) : f(q, v + h * e);
    const VecX minus = wrt_q ? f(integrate_posture(m, q, -h * e), v) : f(q, v - h * e);
    J.col(k) = (plus - minus) / (2 * h);
  }
  return J;
}

// Richardson: (4 D(h/2) − D(h)) / 3 cancels the h² term of the central difference.
inline MatX richardson(const Model& m, const Function& f, const VecX& q, const VecX& v,
                       bool wrt_q) {
  const double h = 1e-3;
  return (4 * central(m, f, q, v, wrt_q, h / 2) - central(m, f, q, v, wrt_q, h)) / 3;
}

}  // namespace femdyn::test
