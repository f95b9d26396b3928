// A run's report as JSON, the one set of fields every door gives: `femdyn simulate --json`
// prints simulation_json, femdyn.simulate returns it as its stats, and Simulator.run returns
// run_summary_json's fields beside its own (python/bind_simulator.cpp).
#pragma once
#include <nlohmann/json.hpp>

#include "sim/simulation_request.hpp"

namespace femdyn {

using Json = nlohmann::json;

// What a watched run found (sim/recorded_run.hpp): the energy balance, limit crossings,
// velocity excesses, effort saturations and, with closed loops, the constraints' residuals
// ("loops": max_position_residual, max_velocity_residual).
Json run_summary_json(const Model& model, const RecordedRun& run, bool conservative);

// The whole run: the model, the integrator and its setting, the statistics, the summary above,
// the loops' assembly, "ok", "diverged" and "failure" ("" when ok).
Json simulation_json(const Model& model, const SimulationRequest& request,
                     const SimulationReport& report);

}  // namespace femdyn
