// One state's analytic derivatives for the Python bindings, shared by the single calls
// (bind_derivatives.cpp) and their batch forms (bind_batch.cpp), so that a batch row is the
// single call's arithmetic exactly.
#pragma once
#include <string>

#include "core/derivatives.hpp"
#include "python/arrays.hpp"

namespace femdyn::python {

inline void require_finite(const MatX& x, const char* what) {
  if (!x.allFinite())
    throw NumericalError(std::string("at this state ") + what +
                         " is NaN or Inf (the state overflows double precision)");
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

}  // namespace femdyn::python
