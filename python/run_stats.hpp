// A run's summary as the Python module returns it (stats of femdyn.simulate and of
// Simulator.run), from the one RecordedRun every driver fills (sim/recorded_run.hpp): the energy
// balance, limit crossings, velocity excesses, effort saturations and, with closed loops, the
// constraints' residuals — the fields `femdyn simulate --json` prints.
#pragma once
#include "python/arrays.hpp"
#include "sim/recorded_run.hpp"

namespace femdyn::python {

// Adds the run's fields to `stats`; `conservative`: nothing but conservative forces acted.
void put_run_stats(py::dict& stats, const Model& model, const RecordedRun& run, bool conservative);

}  // namespace femdyn::python
