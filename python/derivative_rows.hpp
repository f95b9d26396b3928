// One state's analytic derivatives for the Python bindings, shared by the single calls
// (bind_derivatives.cpp) and their batch forms (bind_batch.cpp), so that a batch row is the
// single call's arithmetic exactly.
#pragma once
#include <cmath>
#include <optional>
#include <string>

#include "core/derivatives/derivatives.hpp"
#include "python/arrays.hpp"

namespace femdyn::python {

inline void require_finite(const MatX& x, const char* what) {
  if (!x.allFinite()) throw NumericalError(overflow_text(what));
}

// Baumgarte's rate for a closed loop's constrained equations (1/s): the argument, checked, or the
// simulator's default; a rate given to a model without constraints is refused.
inline double baumgarte_arg(const Model& m, const std::optional<double>& baumgarte) {
  if (baumgarte && m.constraints.empty())
    throw py::value_error("baumgarte: the model has no constraints");
  if (baumgarte && (!(*baumgarte >= 0) || !std::isfinite(*baumgarte)))
    throw py::value_error("baumgarte: expected a rate >= 0 (1/s)");
  return baumgarte.value_or(kDefaultBaumgarte);
}

// q̈, ∂q̈/∂q, ∂q̈/∂v and (M^s)⁻¹ at (q, v, τ) into d; a failed forward dynamics or a NaN is a
// NumericalError.
inline void forward_derivatives_at(const Model& m, Workspace& ws, DerivativeWorkspace& d,
                                   const VecX& q, const VecX& v, const VecX& tau) {
  const Status st = forward_dynamics_derivatives(m, ws, d, q, v, tau);
  if (!st.ok) throw NumericalError("at this state " + st.message);
  require_finite(d.dqdd_dq, "dqdd_dq");
  require_finite(d.dqdd_dv, "dqdd_dv");
}

// A and B of the linearisation at (q, v, τ) (linearize_state, as `femdyn linearize`); its failure
// is a NumericalError.
inline void linearize_at(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                         const VecX& v, const VecX& tau, MatX& A, MatX& B) {
  if (const Status st = linearize_state(m, ws, d, q, v, tau, A, B); !st.ok)
    throw NumericalError("at this state " + st.message);
}

}  // namespace femdyn::python
