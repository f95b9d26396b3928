#include "python/run_stats.hpp"

#include <pybind11/stl.h>

namespace femdyn::python {

void put_run_stats(py::dict& stats, const Model& model, const RecordedRun& run, bool conservative) {
  stats["conservative"] = conservative;
  stats["energy_initial"] = run.initial.total();
  stats["energy_balance_error"] = run.max_balance;
  stats["energy_scale"] = run.scale;
  stats["energy_balance_relative"] = run.relative_balance();
  py::list crossings;
  for (const LimitCrossing& c : run.limit_crossings) {
    py::dict x;
    x["joint"] = c.name;
    x["t"] = c.t;
    x["value"] = c.value;
    x["lower"] = c.lower;
    x["upper"] = c.upper;
    crossings.append(x);
  }
  stats["limit_crossings"] = crossings;
  py::list too_fast;
  for (const VelocityExcess& v : run.velocity_excesses) {
    py::dict x;
    x["joint"] = v.name;
    x["t"] = v.t;
    x["value"] = v.value;
    x["limit"] = v.limit;
    too_fast.append(x);
  }
  stats["velocity_excesses"] = too_fast;
  py::list saturated;
  for (const EffortSaturation& e : run.saturations) {
    py::dict x;
    x["coordinate"] = e.name;
    x["limit"] = e.limit;
    x["evaluations"] = e.evaluations;
    saturated.append(x);
  }
  stats["saturations"] = saturated;
  stats["saturated_evaluations"] = run.saturated_evaluations;
  stats["saturated_steps"] = run.saturated_steps;
  stats["unapplied_effort_limits"] = run.unapplied_effort_limits;
  if (!model.constraints.empty()) {  // closed loops: the largest residuals over the rows
    stats["max_position_residual"] = run.max_position_residual;
    stats["max_velocity_residual"] = run.max_velocity_residual;
  }
}

}  // namespace femdyn::python
