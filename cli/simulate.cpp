// femdyn simulate: the motion of a model from an initial state under an actuation, by any of
// the integrators of sim/integrator.hpp, written as a trajectory CSV with the energy balance.
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "core/loops/assembly.hpp"
#include "core/memory.hpp"
#include "core/names.hpp"
#include "io/actuation_table.hpp"
#include "io/atomic_file.hpp"
#include "io/output.hpp"
#include "io/trajectory_csv.hpp"
#include "sim/control_loop.hpp"
#include "sim/integrator.hpp"
#include "sim/recorded_run.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kSimulateHelp =
    R"(usage: femdyn simulate MODEL --t-end T [--integrator rk4|euler|dopri|bdf]
                        [--dt h | --rtol r --atol a] [--q0 …] [--qd0 …] [--tau … | --tau-csv FILE]
                        [--out traj.csv] [--every k | --sample-dt s] [--max-steps N] [--force]
                        [--max-memory GB] [--json] [--gravity gx,gy,gz] [--baumgarte W]
                        [--jacobian analytic|differences]

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
         else differences) or differences (forward differences of forward dynamics always)
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

// The row times 0, s, 2s, …, t_end (the last one exactly t_end).
std::vector<double> output_times(double t_end, double s) {
  std::vector<double> times;
  for (long k = 0; static_cast<double>(k) * s < t_end - 1e-9 * s; ++k)
    times.push_back(static_cast<double>(k) * s);
  times.push_back(t_end);
  return times;
}

// Whether the trajectory file fits on its disk: rows × (2n + 5) numbers of at most 24 bytes
// (a fixed-step run's rows are known up front; an adaptive run's, without --sample-dt, are not).
Status output_fits(const AtomicFile& out, const Model& m, const IntegratorOptions& o, double t_end,
                   long every, const std::optional<std::vector<double>>& times) {
  double rows = 0;
  if (times)
    rows = static_cast<double>(times->size());
  else if (!is_adaptive(o.kind))
    rows = std::ceil(t_end / o.fixed.dt) / static_cast<double>(every) + 2;
  else
    return {};
  const double bytes = rows * (2.0 * m.n() + 5) * 24;
  std::error_code ec;
  const auto space =
      std::filesystem::space(std::filesystem::absolute(out.temporary(), ec).parent_path(), ec);
  if (ec || bytes <= static_cast<double>(space.available)) return {};
  return {false, "the trajectory would take up to " + format_short(bytes / 1e9) + " GB (" +
                     format_short(rows) + " rows) and the disk has " +
                     format_short(static_cast<double>(space.available) / 1e9) +
                     " GB free: write fewer rows (--every k or --sample-dt s)"};
}

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_interrupt(int) { g_interrupted = 1; }

// SIGINT and SIGTERM set a flag the run checks after every step; restored on exit.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_interrupted = 0;
    struct sigaction sa {};
    sa.sa_handler = on_interrupt;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

}  // namespace

IntegratorOptions integrator_options(const Args& a) {
  IntegratorOptions o;
  if (a.has("integrator") && !parse_integrator(a.options.at("integrator"), o.kind))
    throw CliError("--integrator: " + quoted_text(a.options.at("integrator")) +
                   " is not one of rk4, euler, dopri, bdf");
  if (is_adaptive(o.kind)) {
    if (a.has("dt"))
      throw CliError(std::string("--dt sets the step of rk4 and euler; ") +
                     integrator_name(o.kind) + " is adaptive: use --rtol and --atol");
    o.adaptive.rtol = number_option(a, "rtol", o.adaptive.rtol);
    o.adaptive.atol = number_option(a, "atol", o.adaptive.atol);
  } else {
    if (a.has("rtol") || a.has("atol"))
      throw CliError(std::string("--rtol/--atol apply to dopri and bdf; ") +
                     integrator_name(o.kind) + " has a fixed step: use --dt");
    o.fixed.dt = number_option(a, "dt", o.fixed.dt);
  }
  if (a.has("jacobian")) {
    const std::string& how = a.options.at("jacobian");
    if (o.kind != IntegratorKind::Bdf)
      throw CliError("--jacobian applies to bdf, the one integrator that uses a Jacobian");
    if (how != "analytic" && how != "differences")
      throw CliError("--jacobian: " + quoted_text(how) + " is not one of analytic, differences");
    o.adaptive.analytic_jacobian = how == "analytic";
  }
  const long max_steps = static_cast<long>(integer_option(a, "max-steps", 1e7, 1, 1e15));
  o.fixed.max_steps = max_steps;
  if (a.has("max-steps")) o.adaptive.max_steps = max_steps;
  if (const std::string why = o.check(); !why.empty()) throw CliError("--" + why);
  return o;
}

int cmd_simulate(int argc, char** argv) {
  const Args a = parse_args(
      argc, argv, 2, {"help", "json", "force"},
      {"gravity", "t-end", "integrator", "dt", "rtol", "atol", "q0", "qd0", "tau", "tau-csv", "out",
       "every", "sample-dt", "max-steps", "max-memory", "baumgarte", "jacobian"});
  if (a.has("help")) {
    std::cout << kSimulateHelp;
    return 0;
  }
  const Model m = load(a);
  if (!a.has("t-end")) throw CliError("--t-end is required (try --help)");
  const double t_end = number_option(a, "t-end", 0);
  if (!(t_end > 0) || t_end > 1e9) throw CliError("--t-end expects a time in (0, 1e9] s");
  const IntegratorOptions o = integrator_options(a);
  VecX q0 = configuration_vector(a, "q0", m), qd0 = state_vector(a, "qd0", m);
  // Closed loops: the start assembled onto the constraints (docs/loops.md).
  StateAssembly loops;
  double baumgarte = Motion::kDefaultBaumgarte;
  if (a.has("baumgarte")) {
    if (m.constraints.empty()) throw CliError("--baumgarte: the model has no constraints");
    baumgarte = number_option(a, "baumgarte", 0);
    if (!(baumgarte >= 0) || !std::isfinite(baumgarte))
      throw CliError("--baumgarte expects a rate >= 0 (1/s; 0: off)");
  }
  if (!m.constraints.empty()) {
    loops = assemble_state(m, q0, qd0);
    if (!loops.assembly.status.ok)
      throw StateError(a.positional[0] + ": the initial state: " + loops.assembly.status.message);
  }
  const long every = static_cast<long>(integer_option(a, "every", 1, 1));
  if (a.has("every") && a.has("sample-dt"))
    throw CliError("--every and --sample-dt exclude each other");
  // Memory: the run's matrices and the sample times, before either is allocated.
  const double memory_given = max_memory(a);
  double sample_dt = 0;
  if (a.has("sample-dt")) {
    sample_dt = number_option(a, "sample-dt", 0);
    if (!(sample_dt > 0) || t_end / sample_dt > 1e9)
      throw CliError("--sample-dt expects a positive interval, at most 1e9 rows over --t-end");
  }
  const double run_bytes =
      integrator_bytes(m, o.kind) + (sample_dt > 0 ? 8 * (std::ceil(t_end / sample_dt) + 1) : 0);
  require_memory(a.positional[0] + ": simulating n = " + std::to_string(m.n()) +
                     " coordinates with " + integrator_name(o.kind) +
                     (sample_dt > 0 ? " and " + format_short(std::ceil(t_end / sample_dt) + 1) +
                                          " sample times"
                                    : std::string()),
                 run_bytes, memory_given,
                 "use " + max_memory_option(run_bytes) + " if that much memory is free" +
                     (sample_dt > 0 ? ", or a larger --sample-dt" : "") +
                     (o.kind == IntegratorKind::Bdf ? ", or dopri (no Jacobian)" : ""));
  std::optional<std::vector<double>> sample_times;
  if (sample_dt > 0) sample_times = output_times(t_end, sample_dt);

  // τ: constant, a table, or none (passive).
  if (a.has("tau") && a.has("tau-csv")) throw CliError("--tau and --tau-csv exclude each other");
  Actuation tau;
  std::optional<ActuationTable> table;
  bool driven = false;
  if (a.has("tau")) {
    const VecX u = state_vector(a, "tau", m);
    if (const std::string bad = unactuated_problem(m, u); !bad.empty())
      throw CliError("--tau: " + bad);
    driven = !u.isZero(0);
    if (driven) tau = [u](double, VecX& out) { out = u; };
  } else if (a.has("tau-csv")) {
    table.emplace(a.options.at("tau-csv"), m, memory_given);
    if (table->t_first() > 0 || table->t_last() < t_end)
      throw CliError("--tau-csv " + table->path() + " covers t in [" + num(table->t_first()) +
                     ", " + num(table->t_last()) + "] s; it must cover [0, " + num(t_end) + "] s");
    if (const std::string bad = unactuated_problem(m, table->largest()); !bad.empty())
      throw CliError("--tau-csv " + table->path() + ": " + bad);
    tau = [&table](double t, VecX& out) { (*table)(t, out); };
    driven = true;
  }
  const bool is_conservative = conservative(m, driven);

  // Output: refused before any work if it would clobber a file.
  std::optional<AtomicFile> out;
  if (a.has("out")) {
    const std::string& path = a.options.at("out");
    std::error_code ec;
    if (std::filesystem::equivalent(path, a.positional[0], ec))
      throw CliError("--out " + path + " is the model file itself");
    try {
      out.emplace(path, a.has("force"));
    } catch (const std::runtime_error& e) {
      throw CliError(std::string("--out ") + e.what());
    }
  }

  std::unique_ptr<Integrator> integ = make_integrator(m, o, tau);
  integ->motion().set_baumgarte(baumgarte);
  integ->reset(0, q0, qd0, t_end);
  if (out) {
    const Status fits = output_fits(*out, m, o, t_end, every, sample_times);
    if (!fits.ok) throw CliError("--out " + out->path() + ": " + fits.message);
    write_trajectory_header(out->stream(), m);
  }
  InterruptGuard guard;
  Progress progress(t_end, "s");
  const RecordedRun run = run_recorded(
      *integ, t_end, every, sample_times ? &*sample_times : nullptr,
      [&](const Integrator& i, const Energy& E) {
        if (out) write_trajectory_row(out->stream(), i.t(), i.state(), E);
      },
      [&](double t) {
        progress.update(t);
        return g_interrupted != 0;
      });
  progress.finish();
  if (run.interrupted) {
    std::cerr << "femdyn simulate: interrupted at t = " << integ->t() << " s"
              << (out ? "; " + escaped(out->path()) + " was not written" : std::string()) << "\n";
    return 130;  // `out` discards its temporary file
  }
  const Status& st = run.status;
  if (run.refused)  // by the plan, before any work
    throw CliError(std::string(a.positional[0]) + ": " + st.message);
  const Energy& E0 = run.initial;
  const double max_balance = run.max_balance, scale = run.scale, wall = run.wall_time;
  const long rows = run.rows;
  if (out) out->commit();
  if (!a.has("json"))  // (with --json they are the object's "limit_crossings")
    for (const LimitCrossing& c : run.limit_crossings)
      std::cerr << "femdyn simulate: warning: joint '" << c.name << "' left its limits ["
                << num(c.lower) << ", " << num(c.upper) << "] at t = " << num(c.t) << " s (value "
                << num(c.value) << ")"
                << (m.bodies[m.theta_joint[c.joint]].joint.stop
                        ? "; its stop is compliant (docs/control.md)"
                        : "; limits are not enforced")
                << "\n";
  if (!a.has("json")) {
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
                << run.saturated_evaluations << " of " << integ->stats().rhs_evals
                << " evaluations and " << run.saturated_steps << " steps (";
      for (std::size_t k = 0; k < run.saturations.size(); ++k)
        std::cerr << (k ? ", " : "") << run.saturations[k].name << " at ±"
                  << num(run.saturations[k].limit) << ": " << run.saturations[k].evaluations;
      std::cerr << ")\n";
    }
  }

  const IntegratorStats& s = integ->stats();
  const double simulated = integ->t();
  const double rtf = s.wall_time > 0 ? simulated / s.wall_time : 0;
  const std::string balance_name = is_conservative ? "energy drift" : "energy-balance error";
  if (a.has("json")) {
    Json j = {{"model", m.name},
              {"n", m.n()},
              {"coordinates", m.coordinate_names},
              {"integrator", integ->name()},
              {"t_end", t_end},
              {"t_reached", simulated},
              {"steps", s.steps},
              {"rejected", s.rejected},
              {"rhs_evals", s.rhs_evals},
              {"jac_evals", s.jac_evals},
              {"wall_time", wall},
              {"integration_time", s.wall_time},
              {"real_time_factor", rtf},
              {"conservative", is_conservative},
              {"energy_initial", E0.total()},
              {"energy_balance_error", max_balance},
              {"energy_scale", scale},
              {"energy_balance_relative", run.relative_balance()},
              {"rows", rows},
              {"ok", st.ok},
              {"diverged", st.diverged}};
    Json crossings = Json::array();
    for (const LimitCrossing& c : run.limit_crossings)
      crossings.push_back({{"joint", c.name},
                           {"t", c.t},
                           {"value", c.value},
                           {"lower", c.lower},
                           {"upper", c.upper}});
    j["limit_crossings"] = crossings;
    Json too_fast = Json::array(), saturated = Json::array();
    for (const VelocityExcess& v : run.velocity_excesses)
      too_fast.push_back({{"joint", v.name}, {"t", v.t}, {"value", v.value}, {"limit", v.limit}});
    for (const EffortSaturation& e : run.saturations)
      saturated.push_back(
          {{"coordinate", e.name}, {"limit", e.limit}, {"evaluations", e.evaluations}});
    j["velocity_excesses"] = too_fast;
    j["saturations"] = saturated;
    j["saturated_evaluations"] = run.saturated_evaluations;
    j["saturated_steps"] = run.saturated_steps;
    j["unapplied_effort_limits"] = run.unapplied_effort_limits;
    if (is_adaptive(o.kind))
      j["options"] = {{"rtol", o.adaptive.rtol}, {"atol", o.adaptive.atol}};
    else
      j["options"] = {{"dt", o.fixed.dt}};
    if (!m.constraints.empty())
      j["loops"] = {{"equations", m.constraint_rows},
                    {"rank", loops.assembly.rank},
                    {"redundant", loops.assembly.redundant},
                    {"assembly_iterations", loops.assembly.iterations},
                    {"assembly_residual", loops.assembly.residual},
                    {"initial_velocity_change", loops.velocity_change},
                    {"baumgarte", baumgarte},
                    {"max_position_residual", run.max_position_residual},
                    {"max_velocity_residual", run.max_velocity_residual}};
    if (out) j["out"] = out->path();
    if (!st.ok) j["failure"] = st.message;
    std::cout << json_text(j) << "\n";
  } else {
    std::cout << "model: " << m.name << " (" << m.n() << " coordinates)\n"
              << "integrator: " << integ->name() << " ("
              << (is_adaptive(o.kind)
                      ? "rtol " + num(o.adaptive.rtol) + ", atol " + num(o.adaptive.atol)
                      : "dt " + num(o.fixed.dt) + " s")
              << ")\n"
              << "simulated " << num(simulated) << " of " << num(t_end) << " s: " << s.steps
              << " steps (" << s.rejected << " rejected), " << s.rhs_evals
              << " evaluations of forward dynamics, " << s.jac_evals << " Jacobians\n"
              << "wall time " << num(wall) << " s (integration " << num(s.wall_time)
              << " s), real-time factor " << num(rtf) << "\n"
              << balance_name << ": max |E(t) - E(0) - W(t)| = " << num(max_balance) << " J ("
              << num(run.relative_balance()) << " of the " << num(scale)
              << " J the motion started with and was given) over " << rows << " rows\n";
    if (!m.constraints.empty())
      std::cout << "loops: " << m.constraint_rows << " constraint equations, rank "
                << loops.assembly.rank << " (" << loops.assembly.redundant << " redundant); start "
                << "assembled in " << loops.assembly.iterations
                << " Newton iterations (|Phi| = " << num(loops.assembly.residual)
                << "), velocity projected (|dv| = " << num(loops.velocity_change)
                << "); Baumgarte rate " << num(baumgarte) << " 1/s\n"
                << "constraint residual over the rows: max |Phi| = "
                << num(run.max_position_residual)
                << ", max |Phi_q v| = " << num(run.max_velocity_residual) << "\n";
    if (out) std::cout << "wrote " << escaped(out->path()) << " (" << rows << " rows)\n";
  }
  if (!st.ok) {
    std::cerr << "femdyn simulate: " << escaped(a.positional[0]) << ": " << safe_message(st.message)
              << (out ? "; the rows up to t = " + num(simulated) + " s are in " +
                            escaped(out->path())
                      : std::string())
              << "\n";
    return 1;
  }
  return 0;
}

}  // namespace femdyn::cli
