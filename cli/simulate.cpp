// femdyn simulate: the motion of a model from an initial state under an actuation, by any of
// the integrators of sim/integrator.hpp, written as a trajectory CSV with the energy balance.
#include <algorithm>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/commands.hpp"
#include "cli/interrupt.hpp"
#include "cli/progress.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/actuation_table.hpp"
#include "io/atomic_file.hpp"
#include "io/output.hpp"
#include "io/trajectory_csv.hpp"
#include "models/model_files.hpp"
#include "sim/run_report.hpp"
#include "sim/simulation_request.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kSimulateHelp =
    R"(usage: femdyn simulate MODEL --t-end T [--integrator rk4|euler|dopri|bdf]
                        [--dt h | --rtol r --atol a] [--q0 …] [--qd0 …] [--tau … | --tau-csv FILE]
                        [--out traj.csv] [--every k | --sample-dt s] [--max-steps N] [--force]
                        [--max-memory GB] [--json] [--gravity gx,gy,gz] [--baumgarte W]
                        [--jacobian analytic|differences] [--max-order K]

Integrates M^s q̈ + h = Q from (q0, q̇0) (default 0) over [0, T] and prints a summary:
integrator, steps, rejected steps, evaluations of forward dynamics, Jacobians, wall time,
real-time factor (simulated time / integration wall time), and the energy balance: the largest
|E(t) − E(0) − W(t)| over the output rows, W the work of the non-conservative forces (τ,
dampers, friction, joint stops, body torques); for a conservative model that is the energy drift. It is given
relative to the energy the motion started with plus the work done (docs/simulation.md).

A model with closed loops (constraints, docs/loops.md) starts from q0 assembled onto the
constraints by Newton's least-norm steps and q̇0 projected onto them (an impulse through the
loops); it moves by the constrained equations with Baumgarte's stabilisation at --baumgarte W
(1/s, default 20; 0: off), and is projected back onto the constraints after every fixed step, and
after every adaptive step that leaves them by more than 10 (atol + rtol |y|). The summary gives the equations,
their rank (redundant ones counted) and the largest residuals |Phi| and |Phi_q v| over the rows.

integrators (docs/simulation.md):
  rk4    classical Runge–Kutta 4, fixed step --dt (default 1e-3 s)
  euler  semi-implicit (symplectic) Euler, fixed step --dt (default 1e-3 s)
  dopri  Dormand–Prince 5(4), adaptive (SUNDIALS ARKODE), --rtol (1e-6) --atol (1e-8); default
  bdf    BDF orders 1–5 with Newton (SUNDIALS CVODE), for stiff models; --rtol --atol;
         --jacobian analytic (default: the analytic derivatives where they cover the model,
         else differences) or differences (forward differences of forward dynamics always);
         --max-order K (1–5, default 5): 2 for undamped fast oscillation (a flexible bar's
         axial modes), where orders 3–5 are unstable at large steps and 1–2 are not
--tau a,b,… is a constant actuation on the coordinates; --tau-csv FILE a time table with the
header t,<coordinate>,… (or tau_<coordinate>), interpolated linearly; it must cover [0, T].
--out writes t, q_*, qd_*, kinetic, potential, total, work every k-th step (--every, default 1;
the first and last rows always, the last at T exactly), or at the times 0, s, 2s, …, T
(--sample-dt s; adaptive methods interpolate there, fixed-step ones land there with a
shortened step and return to their grid t = k dt). The file appears whole when the run ends:
an existing file is
kept unless --force, and a failed or interrupted run never leaves half a file (a run stopped by
a numerical fault writes the rows up to the last good step and says so). --json prints the
summary as one object.
Before it starts, a fixed-step run that needs more than --max-steps steps (default 1e7) or a
dt below the time's resolution is refused with its step count and estimated time, and an
output larger than the free disk space is refused with its size, and a run whose memory (the
model's n x n matrices, bdf's Jacobian, the --sample-dt times, the --tau-csv table) exceeds the
memory limit (--max-memory GB, default half the available memory) with the memory it needs. An
adaptive run (dopri, bdf) over less than 1e-100 s is refused. A solution that diverges
(its energy grows far beyond what it started with and was given) stops as a failure that names
the stiffest mode and the step it allows. A joint that leaves its declared limits gets one
warning (the joint, the time, the value), as does one faster than its velocity limit; tau is
saturated at the joints' effort limits, and the saturated evaluations and steps are counted and
warned of (docs/control.md). Exit 1 on a numerical fault or a divergence (the
message names the time, the quantity and the likely cause), 130 when interrupted.
)";

std::string num(double x) { return format_number(x, "%.4g"); }

// Whether the trajectory file fits on its disk: rows × (2n + 5) numbers of at most 24 bytes
// (a fixed-step run's rows are known up front; an adaptive run's, without --sample-dt, are not).
Status output_fits(const AtomicFile& out, const Model& m, const SimulationRequest& r) {
  double rows = 0;
  if (r.times)
    rows = static_cast<double>(r.times->size());
  else if (!is_adaptive(r.options.kind))
    rows = std::ceil(r.t_end / r.options.fixed.dt) / static_cast<double>(r.row_every()) + 2;
  else
    return {};
  const double bytes = rows * (2.0 * m.n() + 5) * 24;
  const double free = out.shortfall(bytes);
  if (free == 0) return {};
  return {false, "the trajectory would take up to " + format_short(bytes / 1e9) + " GB (" +
                     format_short(rows) + " rows) and the disk has " + format_short(free / 1e9) +
                     " GB free: write fewer rows (--every k or --sample-dt s)"};
}

// The command line's spelling of the request's options: --t-end, --tau-csv FILE, --max-memory.
Door command_line(const Args& a) {
  const std::string tau_csv = a.has("tau-csv") ? " " + a.options.at("tau-csv") : "";
  return {[tau_csv](std::string_view name) {
            std::string o = "--" + std::string(name);
            std::replace(o.begin(), o.end(), '_', '-');
            return o == "--tau-csv" ? o + tau_csv : o;
          },
          [](double bytes) {
            return "use " + max_memory_option(bytes) + " if that much memory is free";
          }};
}

std::optional<double> optional_number(const Args& a, const std::string& name) {
  if (!a.has(name)) return std::nullopt;
  return number_option(a, name, 0);
}

std::optional<std::string> optional_text(const Args& a, const std::string& name) {
  if (!a.has(name)) return std::nullopt;
  return a.options.at(name);
}

// The command line as a request: the options translated, τ read (a table from its file).
SimulationRequest simulation_request(const Args& a, const Model& m, const Door& door,
                                     std::optional<ActuationTable>& table) {
  if (!a.has("t-end")) throw CliError("--t-end is required (try --help)");
  SimulationRequest r;
  r.t_end = number_option(a, "t-end", 0);
  r.options = integrator_options(
      {optional_text(a, "integrator"), optional_number(a, "dt"), optional_number(a, "rtol"),
       optional_number(a, "atol"), optional_text(a, "jacobian"), optional_number(a, "max-steps"),
       optional_number(a, "max-order")},
      door);
  r.q0 = configuration_vector(a, "q0", m);
  r.qd0 = state_vector(a, "qd0", m);
  r.baumgarte = optional_number(a, "baumgarte");
  r.every = optional_number(a, "every");
  r.sample_dt = optional_number(a, "sample-dt");
  r.max_memory = max_memory(a);
  if (a.has("tau") && a.has("tau-csv")) throw CliError("--tau and --tau-csv exclude each other");
  if (a.has("tau")) {
    const VecX u = state_vector(a, "tau", m);
    r.tau_largest = u.cwiseAbs();
    if (!u.isZero(0)) r.tau = [u](double, VecX& out) { out = u; };
  } else if (a.has("tau-csv")) {
    table.emplace(a.options.at("tau-csv"), m, r.max_memory);
    r.tau_option = "tau_csv";
    r.tau_span = {table->t_first(), table->t_last()};
    r.tau_largest = table->largest();
    r.tau = [&table](double t, VecX& out) { (*table)(t, out); };
  }
  return r;
}

// --out, refused before any work if it would clobber a file.
void open_output(const Args& a, std::optional<AtomicFile>& out) {
  if (!a.has("out")) return;
  const std::string& path = a.options.at("out");
  std::vector<RunInput> inputs = model_inputs(a.positional[0]);
  if (a.has("tau-csv")) inputs.emplace_back(a.options.at("tau-csv"), "the --tau-csv file");
  if (const std::string input = input_at(path, inputs); !input.empty())
    throw CliError("--out " + path + " is " + input);
  try {
    out.emplace(path, a.has("force"));
  } catch (const std::runtime_error& e) {
    throw CliError(std::string("--out ") + e.what());
  }
}

// Limit crossings, velocity excesses and saturations, one warning each on stderr.
void print_warnings(const Model& m, const SimulationReport& report) {
  const RecordedRun& run = report.run;
  for (const LimitCrossing& c : run.limit_crossings)
    std::cerr << "femdyn simulate: warning: joint '" << c.name << "' left its limits ["
              << num(c.lower) << ", " << num(c.upper) << "] at t = " << num(c.t) << " s (value "
              << num(c.value) << ")"
              << (m.bodies[m.theta_joint[c.joint]].joint.stop
                      ? "; its stop is compliant (docs/control.md)"
                      : "; limits are not enforced")
              << "\n";
  for (const VelocityExcess& v : run.velocity_excesses)
    std::cerr << "femdyn simulate: warning: joint '" << v.name << "' exceeded its velocity limit "
              << num(v.limit) << " at t = " << num(v.t) << " s (rate " << num(v.value) << ")\n";
  if (!run.unapplied_effort_limits.empty()) {
    std::cerr << "femdyn simulate: warning: the effort limits of the coupled joints";
    for (const std::string& name : run.unapplied_effort_limits) std::cerr << " '" << name << "'";
    std::cerr << " are not applied (tau acts on the coordinates they follow)\n";
  }
  if (run.saturated_evaluations > 0) {
    std::cerr << "femdyn simulate: warning: tau saturated at the effort limits in "
              << run.saturated_evaluations << " of " << report.stats.rhs_evals
              << " evaluations and " << run.saturated_steps << " steps (";
    for (std::size_t k = 0; k < run.saturations.size(); ++k)
      std::cerr << (k ? ", " : "") << run.saturations[k].name << " at ±"
                << num(run.saturations[k].limit) << ": " << run.saturations[k].evaluations;
    std::cerr << ")\n";
  }
}

// The summary as text: the integrator, the steps, the time, the energy balance, the loops.
void print_summary(const Model& m, const SimulationRequest& request,
                   const SimulationReport& report) {
  const IntegratorStats& s = report.stats;
  const RecordedRun& run = report.run;
  const IntegratorOptions& o = request.options;
  std::cout << "model: " << m.name << " (" << m.n() << " coordinates)\n"
            << "integrator: " << report.integrator << " ("
            << (is_adaptive(o.kind)
                    ? "rtol " + num(o.adaptive.rtol) + ", atol " + num(o.adaptive.atol)
                    : "dt " + num(o.fixed.dt) + " s")
            << ")\n"
            << "simulated " << num(report.t_reached) << " of " << num(request.t_end)
            << " s: " << s.steps << " steps (" << s.rejected << " rejected), " << s.rhs_evals
            << " evaluations of forward dynamics, " << s.jac_evals << " Jacobians\n"
            << "wall time " << num(run.wall_time) << " s (integration " << num(s.wall_time)
            << " s), real-time factor " << num(report.real_time_factor()) << "\n"
            << (report.conservative ? "energy drift" : "energy-balance error")
            << ": max |E(t) - E(0) - W(t)| = " << num(run.max_balance) << " J ("
            << num(run.relative_balance()) << " of the " << num(run.scale)
            << " J the motion started with and was given) over " << run.rows << " rows\n";
  if (m.constraints.empty()) return;
  const AssemblyReport& a = report.loops.assembly;
  std::cout << "loops: " << m.constraint_rows << " constraint equations, rank " << a.rank << " ("
            << a.redundant << " redundant); start assembled in " << a.iterations
            << " Newton iterations (|Phi| = " << num(a.residual)
            << "), velocity projected (|dv| = " << num(report.loops.velocity_change)
            << "); Baumgarte rate " << num(report.baumgarte) << " 1/s\n"
            << "constraint residual over the rows: max |Phi| = " << num(run.max_position_residual)
            << ", max |Phi_q v| = " << num(run.max_velocity_residual) << "\n";
}

}  // namespace

int cmd_simulate(int argc, char** argv) {
  const Args a = parse_args(
      argc, argv, 2, {"help", "json", "force"},
      {"gravity", "t-end", "integrator", "dt", "rtol", "atol", "q0", "qd0", "tau", "tau-csv", "out",
       "every", "sample-dt", "max-steps", "max-memory", "baumgarte", "jacobian", "max-order"});
  if (a.has("help")) {
    std::cout << kSimulateHelp;
    return 0;
  }
  const Model m = load(a);
  const Door door = command_line(a);
  std::optional<ActuationTable> table;
  SimulationRequest request;
  StateAssembly loops;
  try {
    request = simulation_request(a, m, door, table);
  } catch (const RequestError& e) {
    throw CliError(e.what());
  }
  try {
    loops = check_request(m, request, door);
  } catch (const RequestError& e) {
    throw CliError(e.what());
  } catch (const StateError& e) {
    throw StateError(a.positional[0] + ": " + e.what());
  } catch (const MemoryRefused& e) {
    throw MemoryRefused(a.positional[0] + ": simulating " + e.what());
  }
  std::optional<AtomicFile> out;
  open_output(a, out);
  if (out) {
    const Status fits = output_fits(*out, m, request);
    if (!fits.ok) throw CliError("--out " + out->path() + ": " + fits.message);
    write_trajectory_header(out->stream(), m);
  }
  InterruptGuard guard;
  Progress progress(request.t_end, "s");
  const SimulationReport report = run_simulation(
      m, request, loops,
      [&](const Integrator& i, const Energy& E) {
        if (out) write_trajectory_row(out->stream(), i.t(), i.state(), E);
      },
      [&](double t) {
        progress.update(t);
        return g_interrupted != 0;
      });
  progress.finish();
  const RecordedRun& run = report.run;
  if (run.interrupted) {
    std::cerr << "femdyn simulate: interrupted at t = " << report.t_reached << " s"
              << (out ? "; " + escaped(out->path()) + " was not written" : std::string()) << "\n";
    return 130;  // `out` discards its temporary file
  }
  if (run.refused)  // by the plan, before any work
    throw CliError(std::string(a.positional[0]) + ": " + run.status.message);
  if (out) out->commit();
  if (a.has("json")) {  // (the warnings are the object's lists)
    Json j = simulation_json(m, request, report);
    if (out) j["out"] = out->path();
    std::cout << json_text(j) << "\n";
  } else {
    print_warnings(m, report);
    print_summary(m, request, report);
    if (out) std::cout << "wrote " << escaped(out->path()) << " (" << run.rows << " rows)\n";
  }
  if (!run.status.ok) {
    std::cerr << "femdyn simulate: " << escaped(a.positional[0]) << ": "
              << safe_message(run.status.message)
              << (out ? "; the rows up to t = " + num(report.t_reached) + " s are in " +
                            escaped(out->path())
                      : std::string())
              << "\n";
    return 1;
  }
  return 0;
}

}  // namespace femdyn::cli
