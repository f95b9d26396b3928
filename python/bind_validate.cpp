// femdyn.validate: the model against its Simbody twin (validation/validate.hpp), as numbers.
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "python/py_model.hpp"
#ifdef FEMDYN_WITH_SIMBODY
#include "validation/file_rows.hpp"
#include "validation/validate.hpp"
#endif

namespace femdyn::python {

#ifdef FEMDYN_WITH_SIMBODY
namespace {

// The options, each checked as the CLI checks its flag.
validation::ValidationOptions validation_options(int states, unsigned seed,
                                                 std::optional<double> tolerance, double t_end,
                                                 int samples, double budget,
                                                 std::optional<double> max_memory) {
  if (states < 1) throw py::value_error("states: expected an integer >= 1");
  // The CLI's limit on --t-end (validation::kMaxTrajectoryTime), shared, not copied.
  if (!(t_end >= 0 && t_end <= validation::kMaxTrajectoryTime))
    throw py::value_error("t_end: " + format_number(t_end, "%.15g") + " is not a time in [0, " +
                          format_number(validation::kMaxTrajectoryTime) +
                          "] s (0: no trajectory; the limit of femdyn validate --t-end)");
  if (samples < 1) throw py::value_error("samples: expected an integer >= 1");
  if (tolerance && !(*tolerance > 0 && *tolerance < 1))
    throw py::value_error("tolerance: expected a number in (0, 1), or None for the default");
  if (!(budget > 0 && budget < 1e9))
    throw py::value_error("budget: expected a positive number of seconds (below 1e9)");
  if (max_memory && !(*max_memory > 0 && *max_memory < 1e9))
    throw py::value_error("max_memory: expected a positive number of GB");
  validation::ValidationOptions o;
  o.states = states;
  o.seed = seed;
  if (tolerance) o.tolerance = *tolerance;
  o.t_end = t_end;
  o.samples = samples;
  o.budget = budget;
  if (max_memory) o.memory_limit = *max_memory * 1e9;
  return o;
}

py::dict quantities_dict(const validation::ValidationReport& r) {
  py::dict quantities;
  for (const validation::QuantityError& q : r.quantities) {
    py::dict d;
    d["max_abs"] = q.max_abs;
    d["max_rel"] = q.max_rel;
    d["tolerance"] = q.tolerance;
    d["pass"] = q.pass();
    quantities[py::str(q.name)] = d;
  }
  return quantities;
}

py::dict trajectory_dict(const validation::TrajectoryReport& t) {
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
  if (!t.stopped.empty()) traj["stopped"] = t.stopped;
  if (!t.refinement.empty()) traj["refinement"] = t.refinement;
  return traj;
}

// As `femdyn validate --json`'s "work".
py::dict work_dict(const validation::ValidationReport& r) {
  const validation::WorkEstimate& e = r.estimate;
  py::dict work;
  work["estimated_s"] = e.seconds();
  work["estimated_pointwise_s"] = e.pointwise;
  work["estimated_trajectory_s"] = e.trajectory;
  work["setup_s"] = e.setup;
  work["wall_time_s"] = r.wall_time;
  work["estimated_memory_bytes"] = e.bytes;
  work["budget_s"] = e.budget;
  work["memory_limit_bytes"] =
      std::isfinite(e.memory_limit) ? py::object(py::float_(e.memory_limit)) : py::none();
  work["mass_comparison"] = r.dense_mass ? "entries" : "products";
  return work;
}

py::dict validate(const PyModel& self, int states, unsigned seed, std::optional<double> tolerance,
                  double t_end, int samples, double budget, std::optional<double> max_memory) {
  const validation::ValidationOptions o =
      validation_options(states, seed, tolerance, t_end, samples, budget, max_memory);
  // Estimated before any state, and refused beyond the budget with the CLI's message.
  validation::ValidationReport r;
  std::string refusal;
  {
    py::gil_scoped_release release;
    validation::Validator v(*self.model, o);
    refusal = v.refusal(self.model->where.empty() ? self.model->name : self.model->where);
    if (refusal.empty()) r = v.run();
    // As `femdyn validate FILE`: the import against the robot file it was read from.
    if (refusal.empty() && !self.source.empty())
      validation::add_file_rows(r, *self.model, self.source, o, self.load);
  }
  if (!refusal.empty()) throw py::value_error(refusal);
  py::dict d;
  d["model"] = r.model;
  d["n"] = r.n;
  d["coordinates"] = self.model->coordinate_names;
  d["states"] = r.states;
  d["quantities"] = quantities_dict(r);
  d["trajectory"] = trajectory_dict(r.trajectory);
  d["notes"] = r.notes;
  d["work"] = work_dict(r);
  d["failure"] = r.failure;
  d["compared"] = !r.not_comparable;
  d["pass"] = r.pass();
  return d;
}

}  // namespace
#endif

void bind_validate(py::module_& m) {
#ifdef FEMDYN_WITH_SIMBODY
  m.def("validate", &validate, py::arg("model"), py::arg("states") = 20, py::arg("seed") = 1,
        py::arg("tolerance") = py::none(), py::arg("t_end") = 0.25, py::arg("samples") = 50,
        py::arg("budget") = validation::kDefaultBudget, py::arg("max_memory") = py::none(),
        "The model against its Simbody twin (docs/validation.md): M, h, Q, qdd, tau at `states` "
        "seeded random states and a passive trajectory of t_end s (what `femdyn validate` does, "
        "with its rows for the URDF or MJCF file the model was loaded from: 'urdf import', "
        "'mujoco'); tolerance None is the CLI's default, max(1e-10, eps d^2) "
        "for a tree d bodies deep (q-ddot: at least 10 eps cond(M^s)). Estimated first: beyond "
        "`budget` seconds or `max_memory` "
        "GB (default: half the available memory) a ValueError with `femdyn validate`'s message. "
        "Returns a dict: quantities {name: {max_abs, max_rel, tolerance, pass}}, trajectory "
        "{...}, notes, work, failure, pass. The GIL is released.");
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
