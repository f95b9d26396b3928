// Model.statics: `femdyn statics` for the Python module (sim/statics.hpp), the same solve.
#include <pybind11/stl.h>

#include "core/dynamics/equations.hpp"
#include "python/arrays.hpp"
#include "python/py_model.hpp"
#include "sim/statics.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

Vec3 entry(const py::dict& d, const char* key, const char* what) {
  if (!d.contains(key)) return Vec3::Zero();
  const Array a = d[key].cast<Array>();
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw py::value_error(std::string("loads: ") + what + " " + key + ": expected shape (3,)");
  const Vec3 v(a.data()[0], a.data()[1], a.data()[2]);
  if (!v.allFinite()) throw py::value_error(std::string("loads: ") + key + " is NaN or Inf");
  return v;
}

// [{"body", "force", "torque", "point"}, …] as the CLI's --load.
std::vector<LoadSpec> loads_arg(const std::optional<py::list>& loads) {
  std::vector<LoadSpec> out;
  if (!loads) return out;
  for (std::size_t i = 0; i < loads->size(); ++i) {
    const py::dict d = (*loads)[i].cast<py::dict>();
    for (const auto& [key, value] : d) {
      const std::string k = key.cast<std::string>();
      if (k != "body" && k != "force" && k != "torque" && k != "point")
        throw py::value_error("loads[" + std::to_string(i) + "]: unknown key '" + k +
                              "' (body, force, torque, point)");
    }
    if (!d.contains("body")) throw py::value_error("loads[" + std::to_string(i) + "]: no body");
    LoadSpec l;
    l.body = text_arg(d["body"].cast<std::string>(), "body");
    l.where = "loads[" + std::to_string(i) + "]";
    l.force = entry(d, "force", l.where.c_str());
    l.torque = entry(d, "torque", l.where.c_str());
    l.point = entry(d, "point", l.where.c_str());
    out.push_back(l);
  }
  return out;
}

py::dict statics(const PyModel& self, const OptArray& tau, const std::optional<py::list>& loads,
                 const OptArray& q0, double tolerance) {
  const Model& m = *self.model;
  if (!(tolerance > 0 && tolerance < 1)) throw py::value_error("tolerance: expected (0, 1)");
  StaticsOptions o;
  if (tau) o.tau = vector_arg(*tau, "tau", m);
  if (q0) o.q0 = configuration_arg(*q0, "q0", m);
  o.loads = loads_arg(loads);
  o.tolerance = tolerance;
  StaticsResult r;
  {
    py::gil_scoped_release release;
    r = solve_statics(*self.spec, o);
  }
  if (!r.status.ok) throw NumericalError(r.status.message);
  Workspace ws(m);
  const VecX zero = VecX::Zero(m.n());
  inverse_dynamics(m, ws, r.q, zero, zero);  // (the poses at q)
  py::dict bodies;
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    bodies[py::str(m.bodies[b].name)] =
        py::array_t<double>(3, Vec3(ws.origin + ws.body[b].p).data());
  py::dict d;
  d["q"] = py::array_t<double>(r.q.size(), r.q.data());
  d["residual"] = r.residual;
  d["scale"] = r.scale;
  d["load_steps"] = r.load_steps;
  d["iterations"] = r.iterations;
  d["bodies"] = bodies;
  if (!m.constraints.empty()) {
    d["multipliers"] = py::array_t<double>(r.multipliers.size(), r.multipliers.data());
    d["constraint_residual"] = r.constraint_residual;
  }
  return d;
}

}  // namespace

void bind_statics(py::module_& m) {
  auto model = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  model.def("statics", &statics, py::arg("tau") = py::none(), py::arg("loads") = py::none(),
            py::arg("q0") = py::none(), py::arg("tolerance") = 1e-10,
            "Where the mechanism rests under its springs, gravity, loads, tau (n,) and `loads` "
            "([{'body', 'force', 'torque', 'point'}], world force and torque at a point of the "
            "body's frame), as `femdyn statics`: Newton with the analytic stiffness and "
            "continuation in the load (sim/statics.hpp). Returns {q, residual, scale, "
            "load_steps, iterations, bodies: {name: origin (3,)}} (with closed loops also "
            "multipliers, the constraint forces μ, and constraint_residual |Φ|∞); raises "
            "femdyn.NumericalError "
            "naming the load factor reached when there is no equilibrium.");
}

}  // namespace femdyn::python
