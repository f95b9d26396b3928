#include "sim/simulation_request.hpp"

#include <chrono>
#include <cmath>

#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "sim/control_loop.hpp"
#include "sim/stability.hpp"

namespace femdyn {
namespace {

// (named for this file alone: the sim library is built as one unity source)
std::string request_time_text(double x) { return format_number(x, "%.4g"); }

// An options check's "field: what" with the field in the door's spelling.
std::string spelled(const std::string& why, const Door& door) {
  const std::size_t colon = why.find(':');
  if (colon == std::string::npos) return why;
  return door.option(why.substr(0, colon)) + why.substr(colon);
}

// The row times 0, s, 2s, …, t_end (the last one exactly t_end).
std::vector<double> sample_times(double t_end, double s) {
  std::vector<double> times;
  for (long k = 0; static_cast<double>(k) * s < t_end - 1e-9 * s; ++k)
    times.push_back(static_cast<double>(k) * s);
  times.push_back(t_end);
  return times;
}

void check_rows(SimulationRequest& r, const Door& door) {
  if (r.every && *r.every < 1)
    throw RequestError(door.option("every") + " expects an integer >= 1");
  const int given = (r.every ? 1 : 0) + (r.sample_dt ? 1 : 0) + (r.times ? 1 : 0);
  if (given > 1)
    throw RequestError(door.option(r.every ? "every" : "sample_dt") + " and " +
                       door.option(r.times ? "t_eval" : "sample_dt") + " exclude each other");
  if (r.sample_dt && (!(*r.sample_dt > 0) || r.t_end / *r.sample_dt > 1e9))
    throw RequestError(door.option("sample_dt") +
                       " expects a positive interval, at most 1e9 rows over " +
                       door.option("t_end"));
  if (r.times)
    for (std::size_t i = 0; i < r.times->size(); ++i) {
      const double t = (*r.times)[i];
      if (!(t >= (i ? (*r.times)[i - 1] : 0.0)) || t > r.t_end)
        throw RequestError(door.option("t_eval") + ": expected nondecreasing times in [0, " +
                           door.option("t_end") + "]; entry " + std::to_string(i) + " is not");
    }
}

void check_tau(const Model& model, const SimulationRequest& r, const Door& door) {
  const std::string option = door.option(r.tau_option);
  if (r.tau_span && ((*r.tau_span)[0] > 0 || (*r.tau_span)[1] < r.t_end))
    throw RequestError(option + " covers t in [" + request_time_text((*r.tau_span)[0]) + ", " +
                       request_time_text((*r.tau_span)[1]) + "] s; it must cover [0, " +
                       request_time_text(r.t_end) + "] s");
  if (r.tau_largest.size())
    if (const std::string bad = unactuated_problem(model, r.tau_largest); !bad.empty())
      throw RequestError(option + ": " + bad);
}

// The run's matrices, the sample times and the rows a door holds, before any is allocated.
void check_memory(const Model& model, const SimulationRequest& r, const Door& door) {
  const IntegratorOptions& o = r.options;
  const double samples = r.sample_dt ? std::ceil(r.t_end / *r.sample_dt) + 1 : 0;
  // Rows, where their number is known: the times asked for, or a fixed-step run's steps.
  double rows = r.times ? static_cast<double>(r.times->size()) : samples;
  if (!r.times && !r.sample_dt && !is_adaptive(o.kind))
    rows = std::min(std::ceil(r.t_end / o.fixed.dt), static_cast<double>(o.fixed.max_steps)) /
               static_cast<double>(r.row_every()) +
           2;
  const double bytes = integrator_bytes(model, o.kind) + 8 * samples + rows * r.bytes_per_row;
  std::string what =
      "n = " + std::to_string(model.n()) + " coordinates with " + integrator_name(o.kind);
  if (samples > 0) what += " and " + format_short(samples) + " sample times";
  if (r.bytes_per_row > 0) what += " and " + format_short(rows) + " rows";
  std::string how = door.more_memory(bytes);
  if (r.sample_dt) how += ", or a larger " + door.option("sample_dt");
  if (r.bytes_per_row > 0)
    how += r.times ? ", or fewer " + door.option("t_eval") + " times"
                   : ", or a larger " + door.option("every");
  if (o.kind == IntegratorKind::Bdf) how += ", or dopri (no Jacobian)";
  require_memory(what, bytes, r.max_memory, how);
}

}  // namespace

IntegratorOptions integrator_options(const IntegratorChoice& c, const Door& door) {
  IntegratorOptions o;
  if (c.integrator && !parse_integrator(*c.integrator, o.kind))
    throw RequestError(door.option("integrator") + ": " + quoted_text(*c.integrator) +
                       " is not one of rk4, euler, dopri, bdf");
  const std::string name = integrator_name(o.kind);
  if (is_adaptive(o.kind)) {
    if (c.dt)
      throw RequestError(door.option("dt") + " sets the step of rk4 and euler; " + name +
                         " is adaptive: use " + door.option("rtol") + " and " +
                         door.option("atol"));
    o.adaptive.rtol = c.rtol.value_or(o.adaptive.rtol);
    o.adaptive.atol = c.atol.value_or(o.adaptive.atol);
  } else {
    if (c.rtol || c.atol)
      throw RequestError(door.option("rtol") + "/" + door.option("atol") +
                         " apply to dopri and bdf; " + name + " has a fixed step: use " +
                         door.option("dt"));
    o.fixed.dt = c.dt.value_or(o.fixed.dt);
  }
  if (c.jacobian) {
    if (o.kind != IntegratorKind::Bdf)
      throw RequestError(door.option("jacobian") +
                         " applies to bdf, the one integrator that uses a Jacobian");
    if (*c.jacobian != "analytic" && *c.jacobian != "differences")
      throw RequestError(door.option("jacobian") + ": " + quoted_text(*c.jacobian) +
                         " is not one of analytic, differences");
    o.adaptive.analytic_jacobian = *c.jacobian == "analytic";
  }
  if (c.max_order) {
    if (o.kind != IntegratorKind::Bdf)
      throw RequestError(door.option("max_order") +
                         " applies to bdf, the one integrator of "
                         "variable order");
    const double k = *c.max_order;
    if (!(k >= 1 && k <= 5) || k != std::floor(k))
      throw RequestError(door.option("max_order") + " expects an integer in [1, 5]");
    o.adaptive.max_order = static_cast<int>(k);
  }
  if (c.max_steps) {  // the fixed-step plan's limit, and adaptive's per advance
    const double s = *c.max_steps;
    if (!(s >= 1 && s <= 1e15) || s != std::floor(s))
      throw RequestError(door.option("max_steps") + " expects an integer in [1, 1e15]");
    o.fixed.max_steps = o.adaptive.max_steps = static_cast<long>(s);
  }
  if (const std::string why = o.check(); !why.empty()) throw RequestError(spelled(why, door));
  return o;
}

// A Baumgarte rate ω the method cannot follow, refused before any work: the closed loops'
// residual decays as ë + 2ω ė + ω² e = 0 (a double eigenvalue −ω), so a fixed step beyond that
// mode's stable step diverges at once, and an explicit adaptive method takes steps no longer
// than it (dopri: about 3.3/ω): a run needing more than max_steps of them. BDF is stable at any
// ω but, its error test and the projection's restarts following the residual, was measured to
// take about ω t / 10 steps from ω = 1e4 on (the five-bar: 1,669 steps a second at 1e4, 380,941
// at 1e6, 933,607 at 1e7; Andrews' mechanism 1.5e5 a second at 1e6): refused beyond max_steps.
void check_baumgarte(const Model& model, const IntegratorOptions& o, std::optional<double> given,
                     double t_end, const Door& door) {
  const double w = given.value_or(Motion::kDefaultBaumgarte);
  if (model.constraints.empty() || !(w > 0)) return;
  const std::string rate = given ? door.option("baumgarte") + " " + format_short(w)
                                 : "the Baumgarte rate " + format_short(w) + " 1/s";
  if (o.kind == IntegratorKind::Bdf) {
    if (const double steps = t_end * w / 10; steps > static_cast<double>(o.adaptive.max_steps))
      throw RequestError(rate + ": bdf, stable at any rate, still follows the loops' residual " +
                         "with about ω t / 10 steps (measured): " + format_short(steps) +
                         " steps, beyond " + door.option("max_steps") + " (" +
                         format_short(static_cast<double>(o.adaptive.max_steps)) +
                         "); lower the rate (20 to 1000 1/s hold most loops)");
    return;
  }
  const std::optional<double> h = baumgarte_stable_step(w, o.kind);
  if (!h || !std::isfinite(*h)) return;
  const std::string mode = ": the loops' residual decays at −" + format_short(w) + " 1/s, which " +
                           integrator_name(o.kind) + " follows only at steps ≤ " +
                           format_short(*h) + " s";
  if (!is_adaptive(o.kind)) {
    if (o.fixed.dt > *h)
      throw RequestError(rate + mode + ", and " + door.option("dt") + " is " +
                         format_short(o.fixed.dt) + " s: lower the rate to ≤ " +
                         format_short(w * *h / o.fixed.dt) + " 1/s or the step");
    return;
  }
  const double steps = t_end / *h;
  if (steps > static_cast<double>(o.adaptive.max_steps))
    throw RequestError(rate + mode + ": at least " + format_short(steps) + " steps, beyond " +
                       door.option("max_steps") + " (" +
                       format_short(static_cast<double>(o.adaptive.max_steps)) +
                       "); lower the rate (20 to 1000 1/s hold most loops) or use bdf");
}

StateAssembly check_request(const Model& model, SimulationRequest& r, const Door& door) {
  if (!(r.t_end > 0) || r.t_end > 1e9)
    throw RequestError(door.option("t_end") + " expects a time in (0, 1e9] s");
  check_rows(r, door);
  if (r.baumgarte) {
    if (model.constraints.empty())
      throw RequestError(door.option("baumgarte") + ": the model has no constraints");
    if (!(*r.baumgarte >= 0) || !std::isfinite(*r.baumgarte))
      throw RequestError(door.option("baumgarte") + " expects a rate >= 0 (1/s; 0: off)");
  }
  check_baumgarte(model, r.options, r.baumgarte, r.t_end, door);
  check_tau(model, r, door);
  check_memory(model, r, door);
  if (r.sample_dt) r.times = sample_times(r.t_end, *r.sample_dt);
  StateAssembly loops;
  if (!model.constraints.empty()) {  // the start onto the constraints (docs/loops.md)
    loops = assemble_state(model, r.q0, r.qd0);
    if (!loops.assembly.status.ok)
      throw StateError("the initial state: " + loops.assembly.status.message);
  }
  return loops;
}

SimulationReport run_simulation(const Model& model, const SimulationRequest& r,
                                const StateAssembly& loops,
                                const std::function<void(const Integrator&, const Energy&)>& row,
                                const std::function<bool(double t)>& stop) {
  SimulationReport report;
  std::unique_ptr<Integrator> integ = make_integrator(model, r.options, r.tau);
  report.baumgarte = r.baumgarte.value_or(Motion::kDefaultBaumgarte);
  integ->motion().set_baumgarte(report.baumgarte);
  integ->reset(0, r.q0, r.qd0, r.t_end);
  report.run =
      run_recorded(*integ, r.t_end, r.row_every(), r.times ? &*r.times : nullptr, row, stop);
  report.stats = integ->stats();
  report.integrator = integ->name();
  report.t_reached = integ->t();
  report.conservative = conservative(model, r.driven());
  report.loops = loops;
  return report;
}

}  // namespace femdyn
