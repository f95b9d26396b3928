// Model.derivatives, Model.inverse_derivatives and Model.linearize: the analytic derivatives of
// the dynamics at one state (core/derivatives/derivatives.hpp, docs/derivatives.md).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "python/derivative_rows.hpp"
#include "python/py_model.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;
using OptRate = std::optional<double>;

// Refuses, before any work, derivatives whose buffers (twelve n × n matrices bound them, as for
// `femdyn linearize`) and `results` dense n × n results, copied out to numpy, exceed the memory
// limit (femdyn.set_max_memory).
void require_derivative_memory(const Model& m, const char* what, double results) {
  const double n = m.n(), bytes = evaluation_bytes(m) + dense_bytes(12 * n, n) +
                                  2 * results * dense_bytes(n, n);
  require_memory(std::string(what) + " of n = " + std::to_string(m.n()) + " coordinates", bytes, 0,
                 set_max_memory_text(bytes));
}

// The model's derivative buffers, made on first use (a model they do not cover: ModelError).
DerivativeWorkspace& derivative_workspace(PyModel& self) {
  if (!self.derivatives) self.derivatives = std::make_unique<DerivativeWorkspace>(*self.model);
  return *self.derivatives;
}

// q̈ and its derivatives at (q, q̇, τ), after forward dynamics; a model with closed loops at
// Baumgarte's rate `baumgarte` (default the simulator's).
DerivativeWorkspace& forward_at(PyModel& self, const Array& q, const OptArray& qd,
                                const OptArray& tau, const OptRate& baumgarte, VecX& v) {
  const Model& m = *self.model;
  require_derivative_memory(m, "derivatives", 4);
  DerivativeWorkspace& d = derivative_workspace(self);
  d.baumgarte = baumgarte_arg(m, baumgarte);
  v = vector_arg(qd, "qd", m);
  forward_derivatives_at(m, self.ws, d, configuration_arg(q, "q", m), v,
                         vector_arg(tau, "tau", m, Entries::Bounded));
  return d;
}

py::dict forward(PyModel& self, const Array& q, const OptArray& qd, const OptArray& tau,
                 const OptRate& baumgarte) {
  VecX v;
  const DerivativeWorkspace& d = forward_at(self, q, qd, tau, baumgarte, v);
  py::dict out;
  out["qdd"] = d.qdd;
  out["dqdd_dq"] = d.dqdd_dq;
  out["dqdd_dv"] = d.dqdd_dv;
  out["Minv"] = d.Minv;
  return out;
}

py::dict inverse(PyModel& self, const Array& q, const OptArray& qd, const OptArray& qdd) {
  const Model& m = *self.model;
  require_open_tree(m, "inverse_derivatives");
  require_derivative_memory(m, "inverse_derivatives", 2);
  DerivativeWorkspace& d = derivative_workspace(self);
  const VecX qv = configuration_arg(q, "q", m), v = vector_arg(qd, "qd", m),
             a = vector_arg(qdd, "qdd", m);
  inverse_dynamics_derivatives(m, self.ws, d, qv, v, a);
  require_finite(d.dtau_dq, "dtau_dq");
  require_finite(d.dtau_dv, "dtau_dv");
  inverse_dynamics(m, self.ws, qv, v, a);
  py::dict out;
  out["tau"] = VecX(self.ws.tau);
  out["dtau_dq"] = d.dtau_dq;
  out["dtau_dv"] = d.dtau_dv;
  return out;
}

std::pair<MatX, MatX> linearize(PyModel& self, const Array& q, const OptArray& qd,
                                const OptArray& tau, const OptRate& baumgarte) {
  const Model& m = *self.model;
  require_derivative_memory(m, "linearize", 6);  // (A: 4 n², B: up to 2 n²)
  DerivativeWorkspace& d = derivative_workspace(self);
  d.baumgarte = baumgarte_arg(m, baumgarte);
  MatX A, B;
  linearize_at(m, self.ws, d, configuration_arg(q, "q", m), vector_arg(qd, "qd", m),
               vector_arg(tau, "tau", m, Entries::Bounded), A, B);
  return {A, B};
}

}  // namespace

void bind_derivatives(py::module_& m) {
  auto cls = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  cls.def("derivatives", &forward, py::arg("q"), py::arg("qd") = py::none(),
          py::arg("tau") = py::none(), py::arg("baumgarte") = py::none(),
          "Forward dynamics and its analytic derivatives at (q, q̇, τ) as a dict: qdd (n,), "
          "dqdd_dq, dqdd_dv, Minv = dqdd_dtau (n, n); columns over the rates, q moved along "
          "its tangent q ⊕ ξ on spherical and free joints (docs/derivatives.md). Closed loops: "
          "the constrained equations at Baumgarte's rate `baumgarte` (1/s, default 20, the "
          "simulator's), Minv the projected inverse M⁻¹ − Y S⁺ Yᵀ")
      .def("inverse_derivatives", &inverse, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("qdd") = py::none(),
           "Inverse dynamics and its analytic derivatives at (q, q̇, q̈) as a dict: tau (n,), "
           "dtau_dq, dtau_dv (n, n)")
      .def("linearize", &linearize, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(), py::arg("baumgarte") = py::none(),
           "(A, B): d/dt (ξ, v) = A (ξ, v) + B u at the state, A (2n, 2n), B (2n, n_a): u the "
           "actuated coordinates' tau (Model.actuated; all n unless a free base or a joint "
           "with actuated=False is not driven), as `femdyn linearize` prints them");
}

}  // namespace femdyn::python
