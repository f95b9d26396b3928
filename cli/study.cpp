// femdyn study: error against run time for every femdyn and Simbody integrator on one model
// (validation/study.hpp). Writes study.csv, study.gp + study.png (gnuplot) and study.md.
#include "validation/study.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "cli/study_report.hpp"
#include "core/kinematics/sampling.hpp"
#include "io/atomic_file.hpp"
#include "io/csv.hpp"
#include "io/output.hpp"
#include "validation/validate_loops.hpp"

#ifndef FEMDYN_BUILD_TYPE
#define FEMDYN_BUILD_TYPE "unknown"
#endif

namespace femdyn::cli {
namespace {

namespace fs = std::filesystem;
using validation::StudyReport;
using validation::StudyRun;

constexpr const char* kStudyHelp =
    R"(usage: femdyn study MODEL [--t-end T] [--out DIR] [--quick] [--json] [--land-on-samples]
                     [--q0 …] [--qd0 …] [--budget SECONDS] [--force] [--gravity gx,gy,gz]

Error against run time (work-precision) for every femdyn integrator (rk4, euler over steps;
dopri, bdf over tolerances) and every Simbody integrator on the model's Simbody twin (over
accuracies), from the same initial state over [0, T] (default 1 s), sampled at 20 times.

Sampling: by default both engines step freely and interpolate at the samples (femdyn's dopri and
bdf by dense output; Simbody's integrators by Integrator::stepTo with no scheduled event);
--land-on-samples makes both land on every sample instead (femdyn's stop_at_outputs; Simbody's
TimeStepper). rk4 and euler land on the samples either way (steps T/(20·2^k)).

Error: the relative state error, dimensionless: the largest |θ − θ_ref| over the samples and
the joints divided by the reference's largest |θ| (rad), or the same for the rates θ̇ (rad/s),
whichever is larger (prismatic joints: m and m/s, in groups of their own). The reference is
femdyn's Dormand–Prince landing on each sample at rtol 1e-14; its own error is estimated
against rtol 1e-13: runs more accurate than 100x that estimate are unresolved and left out of
the plot and the tables.

Wall time: the integration alone (no sampling, no energies). Every run is made once as a
warm-up (not counted), then timed 5 times (3 if the warm-up took 50 ms or more; 3 with
--quick) and the median kept, femdyn and Simbody runs alternating. The initial state is
--q0/--qd0, or seeded random (q within joint limits and sample ranges, q̇ in ±1, narrowed on a
joint with a sample range, as validate draws them). Where the twin is a
constrained system (a closed loop, or coordinate couplers) and femdyn integrates reduced
coordinates, the ratios say "not the same formulation".

Writes into DIR (default ./study): study.csv (one row per run; '#' comment lines first with the
model, the error's scales, the reference, the sampling, the CPU, its cores and the load average
at the start and end; pandas reads it with comment='#'), study.gp and study.png (the plot,
log-log error against wall time, by gnuplot), study.md (for 1e-3, 1e-6, 1e-9 the fastest
femdyn and Simbody methods, their times and ratio; then every run). Existing files are kept
unless --force. --quick: fewer sweep points and 0.5 s (seconds; for smoke tests).

Bounded work: the sweeps are bounded by their rules (each ends at its first run over 2 s, 0.2 s
with --quick; a warm-up run is stopped at 4 times that). The reference is not, and is estimated
first: its method is run from the start for 0.5 s of wall time (or to T) and its pace
extrapolated to both reference runs. Beyond --budget seconds (default 600) the study is refused
with one line (the estimate, and the --t-end that fits) and exit 1; a reference run still going
at the budget is stopped, and the study fails. On a terminal the estimate is printed first, then
a progress line for each reference run and a line for each run of the sweeps.

--json: the report as one JSON object on stdout instead of the summary table: {"model", "n",
"t_end", "samples", "estimate" {"reference_s", "reference_measured_s",
"probe_t", "probe_wall_s", "budget_s"}, "q0", "qd0", "sampling", "interpolate", "error" (definition and "scales"),
"reference" {"method", "rtol", "error", "resolution"}, "formulation" {"same", "femdyn",
"simbody"}, "timing" {"repeats", "repeats_long", "repeat_below"}, "targets" [{"target",
"femdyn", "simbody", "ratio"}], "runs" [{"engine", "integrator", "setting", "value", "ok",
"resolved", "error", "position_error", "rate_error", "final_error", "energy_drift",
"wall_time", "warm_up_time", "times", "steps", "rhs_evals", "failure"}], "notes", "machine"
{"cpu", "cores", "build", "compiler", "load_start", "load_end"}, "command", "date"}.
A Debug build refuses to time anything.
)";

// gnuplot study.gp in `dir`, rendering into `png`; false if gnuplot is missing or fails.
bool run_gnuplot(const fs::path& dir, const std::string& png) {
  const std::string out = "out='" + png + "'";
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.c_str()) != 0) _exit(127);
    execlp("gnuplot", "gnuplot", "-e", out.c_str(), "study.gp", static_cast<char*>(nullptr));
    _exit(127);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) < 0) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

// The output directory, created, its four files checked before any work (kept without --force).
fs::path output_directory(const Args& a) {
  const fs::path dir = a.has("out") ? fs::path(a.options.at("out")) : fs::path("study");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir))
    throw CliError("--out " + dir.string() + ": cannot create the directory");
  for (const char* f : {"study.csv", "study.gp", "study.png", "study.md"})
    if (fs::exists(dir / f) && !a.has("force"))
      throw CliError((dir / f).string() + ": exists (use --force to replace it)");
  return dir;
}

// The command as the files quote it: without --force, --json and --out, which do not change
// the study.
std::string study_command(const Args& a, int argc, char** argv) {
  std::string command = "femdyn study " + a.positional[0];
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--force" || arg == "--json") continue;
    if (arg == "--out" && i + 1 < argc) {
      ++i;
      continue;
    }
    command += " " + arg;
  }
  return command;
}

// study.csv, study.gp, study.png (when gnuplot runs) and study.md, each whole; whether plotted.
bool write_study(const fs::path& dir, const StudyReport& rep, const std::string& command,
                 const std::string& md) {
  std::error_code ec;
  const auto write = [&](const char* name, const std::string& text) {
    AtomicFile f((dir / name).string(), true);
    f.stream() << text;
    f.commit();
  };
  write("study.csv", csv_text(rep, command));
  write("study.gp", gnuplot_text(rep));
  // gnuplot renders into a temporary name, renamed when it succeeded.
  const bool plotted = run_gnuplot(dir, ".study.png.tmp");
  if (plotted) fs::rename(dir / ".study.png.tmp", dir / "study.png", ec);
  fs::remove(dir / ".study.png.tmp", ec);
  write("study.md", md);
  if (!plotted)
    std::cerr << "femdyn study: warning: gnuplot failed or is missing (apt install gnuplot-nox); "
              << (dir / "study.gp").string() << " is written, study.png is not\n";
  return plotted;
}

void print_study(const fs::path& dir, const StudyReport& rep, const std::string& md, bool plotted) {
  std::cout << "model: " << escaped(rep.model) << " (" << rep.n << " coordinates), t = 0…"
            << rep.t_end << " s, " << rep.runs.size()
            << " runs\nreference: " << rep.reference_method << ", estimated error "
            << format_sci(rep.reference_error) << "\nsampling: " << sampling_short(rep)
            << "; wall time: " << timing_text(rep) << "\n";
  if (!rep.same_formulation) std::cout << "formulation: " << formulation_text(rep) << "\n";
  std::istringstream lines(md);
  std::string line;
  while (std::getline(lines, line))
    if (line.rfind("| target", 0) == 0 || line.rfind("| 1e-", 0) == 0) std::cout << line << "\n";
  std::cout << "wrote " << escaped((dir / "study.csv").string()) << ", study.md, study.gp"
            << (plotted ? ", study.png" : "") << "\n";
}

// The reference's estimate, told on a terminal first; beyond the budget, the one-line refusal.
void check_estimate(const std::string& label, const validation::StudyEstimate& e,
                    const validation::StudyOptions& o, bool tty) {
  const std::string what = "the reference solution (dopri at rtol 1e-14, then 1e-13, over " +
                           format_short(o.t_end) + " s) would take about " +
                           format_duration(e.reference) +
                           " (its method reached t = " + format_short(e.probe_t) + " s in " +
                           format_duration(e.probe_wall) + ")";
  if (e.reference > o.budget) {
    const double fits = 0.8 * o.t_end * o.budget / e.reference;
    throw femdyn::Error(
        label + ": " + what + ", beyond the budget of " + format_number(o.budget, "%.4g") +
        " s: " + (fits >= 1e-6 ? "use --t-end " + format_number(fits, "%.2g") + " or " : "") +
        "raise --budget");
  }
  if (tty)
    std::cerr << "  " << what << "; then the sweeps, each ending at its first run over "
              << format_short(o.quick ? 0.2 : o.run_budget) << " s (a warm-up stopped at "
              << format_short(o.run_limit()) << " s)\n";
}

// A progress line for each reference run, on a terminal.
std::function<void(const std::string&, double)> reference_progress(double t_end) {
  auto bar = std::make_shared<std::optional<Progress>>();
  auto run = std::make_shared<std::string>();
  return [=](const std::string& which, double t) {
    if (which != *run) {
      bar->reset();  // (clears the last run's line)
      bar->emplace(t_end, "s", which + " t =");
      *run = which;
    }
    (*bar)->update(t);
  };
}

}  // namespace

int cmd_study(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "quick", "force", "json", "land-on-samples"},
                            {"gravity", "t-end", "out", "q0", "qd0", "budget"});
  if (a.has("help")) {
    std::cout << kStudyHelp;
    return 0;
  }
#ifndef NDEBUG
  throw CliError("refusing to time a Debug build (build type " FEMDYN_BUILD_TYPE
                 "): rebuild with -DCMAKE_BUILD_TYPE=Release");
#endif
  const Model m = load(a);
  if (!m.prescribed.empty())  // (Simbody's runs would be of the undriven mechanism)
    throw ModelError(a.positional[0], "joint '" + m.prescribed[0].joint +
                                          "' is prescribed in time, which the Simbody twin does "
                                          "not take: a study would compare two mechanisms");
  validation::StudyOptions o;
  o.quick = a.has("quick");
  o.interpolate = !a.has("land-on-samples");
  o.t_end = number_option(a, "t-end", o.quick ? 0.5 : 1.0);
  if (!(o.t_end > 0) || o.t_end > 100) throw CliError("--t-end expects a time in (0, 100] s");
  o.budget = number_option(a, "budget", 600);
  if (!(o.budget > 0 && o.budget < 1e9))
    throw CliError("--budget expects a positive number of seconds (below 1e9)");
  std::mt19937 rng(1);
  o.q0 = a.has("q0") ? configuration_vector(a, "q0", m) : random_posture(m, rng);
  o.qd0 = a.has("qd0") ? state_vector(a, "qd0", m) : random_rates(m, 1.0, rng);
  // A closed loop starts assembled, from the drawn posture or the neutral one, as validate's
  // trajectory does (a given --q0 is assembled by the integrators' reset, or refused).
  if (std::string why;
      !m.constraints.empty() && !a.has("q0") && !validation::consistent_state(m, o.q0, o.qd0, why))
    throw ModelError(a.positional[0], "cannot assemble a start for the loops: " + why);
  // Outputs: checked before any work; each file appears whole.
  const fs::path dir = output_directory(a);
  const std::string command = study_command(a, argc, argv);
  const bool tty = isatty(STDERR_FILENO) == 1;
  validation::StudyEstimate estimate;
  StudyReport rep;
  try {  // (a failed reference, or a start the loops do not close on, names the model)
    estimate = validation::estimate_study(m, o);
    check_estimate(a.positional[0], estimate, o, tty);
    o.reference_progress = reference_progress(o.t_end);
    rep = validation::run_study(m, o, [tty](const std::string& line) {
      if (tty) std::cerr << "  " << line << "\n";
    });
  } catch (const StateError& e) {
    throw ModelError(a.positional[0], e.what());
  }
  const std::string md = markdown_text(rep, command);
  const bool plotted = write_study(dir, rep, command, md);
  if (a.has("json")) {
    std::cout << json_text(report_json(rep, command, o, estimate)) << "\n";
    return 0;
  }
  print_study(dir, rep, md, plotted);
  return 0;
}

}  // namespace femdyn::cli
