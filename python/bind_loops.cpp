// femdyn.Model's closed loops (core/loops/): the constraints, their kinematics, assembly, and the
// constrained dynamics with λ (docs/loops.md).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/loops/assembly.hpp"
#include "core/model/names.hpp"
#include "python/py_model.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

void require_loops(const Model& m) {
  if (m.constraints.empty())
    throw py::value_error("the model has no constraints (\"constraints\" in its file)");
}

py::dict constraint_kinematics_of(PyModel& self, const Array& q, const OptArray& qd) {
  const Model& m = *self.model;
  require_loops(m);
  ConstraintKinematics k(m);
  constraint_kinematics(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m), k);
  py::dict out;
  out["phi"] = k.phi;
  out["J"] = k.J;
  out["bias"] = k.bias;
  return out;
}

py::dict constrained_of(PyModel& self, const Array& q, const OptArray& qd, const OptArray& tau,
                        double baumgarte) {
  const Model& m = *self.model;
  require_loops(m);
  if (!(baumgarte >= 0) || !std::isfinite(baumgarte))
    throw py::value_error("baumgarte: expected a rate >= 0 (1/s)");
  LoopWorkspace lws(m);
  const Status st = constrained_forward_dynamics(
      m, self.ws, lws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m),
      vector_arg(tau, "tau", m, Entries::Bounded), baumgarte);
  if (!st.ok) throw NumericalError("at this state " + st.message);
  py::dict out;
  out["qdd"] = VecX(self.ws.qdd);
  out["lambda"] = VecX(lws.lambda);
  out["constraint_forces"] = VecX(lws.k.J.transpose() * lws.lambda);
  out["rank"] = lws.rank;
  return out;
}

py::dict assemble_of(PyModel& self, const Array& q_in, const OptArray& qd_in,
                     const std::vector<std::string>& hold) {
  const Model& m = *self.model;
  require_loops(m);
  VecX q = configuration_arg(q_in, "q", m), qd = vector_arg(qd_in, "qd", m);
  AssemblyOptions o;
  for (const std::string& name : hold) {
    const auto it = std::find(m.coordinate_names.begin(), m.coordinate_names.end(), name);
    if (it == m.coordinate_names.end())
      throw py::value_error("hold: unknown coordinate " + quoted_text(name));
    o.held.push_back(static_cast<int>(it - m.coordinate_names.begin()));
  }
  StateAssembly s;
  {
    py::gil_scoped_release release;
    s = assemble_state(m, q, qd, o);
  }
  if (!s.assembly.status.ok) throw NumericalError(s.assembly.status.message);
  py::dict out;
  out["q"] = q;
  out["qd"] = qd;
  out["iterations"] = s.assembly.iterations;
  out["residual"] = s.assembly.residual;
  out["rank"] = s.assembly.rank;
  out["redundant"] = s.assembly.redundant;
  return out;
}

}  // namespace

void bind_loops(py::module_& m) {
  auto model = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  model
      .def_property_readonly(
          "constraints",
          [](const PyModel& s) {
            py::list out;
            for (const LoopConstraint& c : s.model->constraints) {
              py::dict d;
              d["name"] = c.name;
              d["type"] = constraint_type_name(c.type);
              d["rows"] = c.rows();
              out.append(d);
            }
            return out;
          },
          "the loop constraints: name, type and number of equations (docs/loops.md)")
      .def("constraint_kinematics", &constraint_kinematics_of, py::arg("q"),
           py::arg("qd") = py::none(),
           "Φ (m,), its Jacobian J = Φ_q (m, n) on the rates and the bias Φ̇_q q̇ (m,) at (q, q̇)")
      .def("constrained_dynamics", &constrained_of, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(), py::arg("baumgarte") = 0.0,
           "q̈ of the closed mechanism (M q̈ + h = Q + Φ_qᵀ λ, Φ_q q̈ = −Φ̇_q q̇ − 2ω Φ̇ − ω² Φ) as "
           "a dict: qdd, lambda, constraint_forces Φ_qᵀ λ and the rank of the constraints; "
           "NumericalError at a dead point")
      .def("assemble", &assemble_of, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("hold") = std::vector<std::string>{},
           "q moved onto the constraints by Newton's least-norm steps (the coordinates named in "
           "hold kept) and q̇ projected onto them: a dict of q, qd, iterations, residual, rank "
           "and redundant; NumericalError when the loops cannot close");
}

}  // namespace femdyn::python
