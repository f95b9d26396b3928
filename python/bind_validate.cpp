// femdyn.validate: the model against its Simbody twin (validation/validate.hpp), as numbers.
#include <pybind11/stl.h>

#include "python/py_model.hpp"
#ifdef FEMDYN_WITH_SIMBODY
#include "validation/validate.hpp"
#endif

namespace femdyn::python {

#ifdef FEMDYN_WITH_SIMBODY
namespace {

py::dict validate(const PyModel& self, int states, unsigned seed, double tolerance, double t_end,
                  int samples) {
  if (states < 1) throw py::value_error("states: expected an integer >= 1");
  // The CLI's limit on --t-end (validation::kMaxTrajectoryTime), shared, not copied.
  if (!(t_end >= 0 && t_end <= validation::kMaxTrajectoryTime))
    throw py::value_error("t_end: " + format_number(t_end, "%.15g") + " is not a time in [0, " +
                          format_number(validation::kMaxTrajectoryTime) +
                          "] s (0: no trajectory; the limit of femdyn validate --t-end)");
  if (samples < 1) throw py::value_error("samples: expected an integer >= 1");
  if (!(tolerance > 0)) throw py::value_error("tolerance: expected a number > 0");
  validation::ValidationOptions o;
  o.states = states;
  o.seed = seed;
  o.tolerance = tolerance;
  o.t_end = t_end;
  o.samples = samples;
  validation::ValidationReport r;
  {
    py::gil_scoped_release release;
    r = validation::validate(*self.model, o);
  }
  py::dict quantities;
  for (const validation::QuantityError& q : r.quantities) {
    py::dict d;
    d["max_abs"] = q.max_abs;
    d["max_rel"] = q.max_rel;
    d["tolerance"] = q.tolerance;
    d["pass"] = q.pass();
    quantities[py::str(q.name)] = d;
  }
  const validation::TrajectoryReport& t = r.trajectory;
  py::dict traj;
  traj["run"] = t.run;
  traj["skipped"] = t.skipped;
  traj["t_end"] = t.t_end;
  traj["max_state_error"] = t.max_state_error;
  traj["rk4_step"] = t.rk4_step;
  traj["rk4_error_estimate"] = t.rk4_error_estimate;
  traj["simbody_error_estimate"] = t.simbody_error_estimate;
  traj["resolved"] = t.resolved;
  traj["tolerance"] = t.tolerance;
  traj["energy_change_femdyn"] = t.energy_change_femdyn;
  traj["energy_change_simbody"] = t.energy_change_simbody;
  traj["t"] = t.t;
  traj["state_error"] = t.error;
  traj["energy_femdyn"] = t.energy_femdyn;
  traj["energy_simbody"] = t.energy_simbody;
  traj["pass"] = t.pass();
  py::dict d;
  d["model"] = r.model;
  d["n"] = r.n;
  d["coordinates"] = self.model->coordinate_names;
  d["states"] = r.states;
  d["quantities"] = quantities;
  d["trajectory"] = traj;
  d["notes"] = r.notes;
  d["failure"] = r.failure;
  d["pass"] = r.pass();
  return d;
}

}  // namespace
#endif

void bind_validate(py::module_& m) {
#ifdef FEMDYN_WITH_SIMBODY
  m.def("validate", &validate, py::arg("model"), py::arg("states") = 20, py::arg("seed") = 1,
        py::arg("tolerance") = 1e-10, py::arg("t_end") = 0.25, py::arg("samples") = 50,
        "The model against its Simbody twin (docs/validation.md): M, h, Q, qdd, tau at `states` "
        "seeded random states and a passive trajectory of t_end s (what `femdyn validate` does, "
        "less its URDF import check). Returns a dict: quantities {name: {max_abs, max_rel, "
        "tolerance, pass}}, trajectory {...}, notes, failure, pass. The GIL is released.");
  // The Simbody integrators that can run in this process: CPodes is among them only if no other
  // SUNDIALS shadows Simbody's bundled copy (validation/twin.hpp); the tests check it is.
  m.def("_simbody_integrators", [] {
    std::vector<std::string> names;
    for (const validation::SimbodyIntegrator i : validation::simbody_integrators())
      names.emplace_back(validation::simbody_integrator_name(i));
    return names;
  });
  m.attr("with_simbody") = true;
#else
  m.attr("with_simbody") = false;
#endif
}

}  // namespace femdyn::python
