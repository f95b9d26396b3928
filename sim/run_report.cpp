#include "sim/run_report.hpp"

#include "core/dynamics/equations.hpp"

namespace femdyn {

Json run_summary_json(const Model& model, const RecordedRun& run, bool conservative) {
  Json j = {{"conservative", conservative},
            {"energy_initial", run.initial.total()},
            {"energy_balance_error", run.max_balance},
            {"energy_scale", run.scale},
            {"energy_balance_relative", run.relative_balance()},
            {"rows", run.rows},
            {"saturated_evaluations", run.saturated_evaluations},
            {"saturated_steps", run.saturated_steps},
            {"unapplied_effort_limits", run.unapplied_effort_limits}};
  Json crossings = Json::array(), too_fast = Json::array(), saturated = Json::array();
  for (const LimitCrossing& c : run.limit_crossings)
    crossings.push_back({{"joint", c.name},
                         {"t", c.t},
                         {"value", c.value},
                         {"lower", c.lower},
                         {"upper", c.upper}});
  for (const VelocityExcess& v : run.velocity_excesses)
    too_fast.push_back({{"joint", v.name}, {"t", v.t}, {"value", v.value}, {"limit", v.limit}});
  for (const EffortSaturation& e : run.saturations)
    saturated.push_back(
        {{"coordinate", e.name}, {"limit", e.limit}, {"evaluations", e.evaluations}});
  j["limit_crossings"] = crossings;
  j["velocity_excesses"] = too_fast;
  j["saturations"] = saturated;
  if (!model.constraints.empty())
    j["loops"] = {{"equations", model.constraint_rows},
                  {"max_position_residual", run.max_position_residual},
                  {"max_velocity_residual", run.max_velocity_residual}};
  return j;
}

Json simulation_json(const Model& model, const SimulationRequest& request,
                     const SimulationReport& report) {
  const IntegratorStats& s = report.stats;
  const Status& st = report.run.status;
  Json j = run_summary_json(model, report.run, report.conservative);
  j.update({{"model", model.name},
            {"n", model.n()},
            {"coordinates", model.coordinate_names},
            {"integrator", report.integrator},
            {"t_end", request.t_end},
            {"t_reached", report.t_reached},
            {"steps", s.steps},
            {"rejected", s.rejected},
            {"rhs_evals", s.rhs_evals},
            {"jac_evals", s.jac_evals},
            {"wall_time", report.run.wall_time},
            {"integration_time", s.wall_time},
            {"real_time_factor", report.real_time_factor()},
            {"ok", st.ok},
            {"diverged", st.diverged},
            {"failure", st.ok ? std::string() : st.message}});
  Json routes = Json::object();  // which algorithms ran (core/dynamics/equations.hpp, route_report)
  for (const auto& [key, name] : route_report(model).fields()) routes[key] = name;
  j["routes"] = routes;
  const IntegratorOptions& o = request.options;
  if (is_adaptive(o.kind))
    j["options"] = {{"rtol", o.adaptive.rtol}, {"atol", o.adaptive.atol}};
  else
    j["options"] = {{"dt", o.fixed.dt}};
  if (!model.constraints.empty()) {
    const AssemblyReport& a = report.loops.assembly;
    j["loops"].update({{"rank", a.rank},
                       {"redundant", a.redundant},
                       {"assembly_iterations", a.iterations},
                       {"assembly_residual", a.residual},
                       {"initial_velocity_change", report.loops.velocity_change},
                       {"baumgarte", report.baumgarte}});
  }
  return j;
}

}  // namespace femdyn
