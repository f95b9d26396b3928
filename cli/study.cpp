// femdyn study: error against run time for every femdyn and Simbody integrator on one model
// (validation/study.hpp). Writes study.csv, study.gp + study.png (gnuplot) and study.md.
#include "validation/study.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "cli/commands.hpp"
#include "core/sampling.hpp"
#include "io/atomic_file.hpp"

#ifndef FEMDYN_BUILD_TYPE
#define FEMDYN_BUILD_TYPE "unknown"
#endif

namespace femdyn::cli {
namespace {

namespace fs = std::filesystem;
using validation::StudyReport;
using validation::StudyRun;

constexpr const char* kHelp =
    R"(usage: femdyn study MODEL [--t-end T] [--out DIR] [--quick] [--q0 …] [--qd0 …] [--force]
                     [--gravity gx,gy,gz]

Error against run time (work-precision) for every femdyn integrator (rk4, euler over steps;
dopri, bdf over tolerances) and every Simbody integrator on the model's Simbody twin (over
accuracies), from the same initial state over [0, T] (default 1 s). The error of a run is the
largest ‖(θ, θ̇) − reference‖∞ over 20 sample times; the reference is femdyn's Dormand–Prince
landing on each sample at rtol 1e-14, and its own error is estimated against rtol 1e-13: runs
more accurate than 100x that estimate are unresolved and left out of the plot and the tables.
Wall time is the integration alone (no sampling, no energies); femdyn and Simbody runs
alternate; runs under 50 ms are repeated (5 times) and the median kept. The initial state is
--q0/--qd0, or seeded random (q within joint limits, q̇ in ±1).

Writes into DIR (default ./study): study.csv (one row per run), study.gp and study.png (the
plot, log-log error against wall time, by gnuplot), study.md (for 1e-3, 1e-6, 1e-9 the fastest
femdyn and Simbody methods, their times and ratio; then every run). Existing files are kept
unless --force. --quick: fewer sweep points and no repeats (seconds; for smoke tests). A Debug
build refuses to time anything.
)";

std::string sci(double x) { return format_number(x, "%.2e"); }

std::string seconds(double t) {
  char buf[32];
  if (t < 1e-3)
    std::snprintf(buf, sizeof buf, "%.1f µs", t * 1e6);
  else if (t < 1)
    std::snprintf(buf, sizeof buf, "%.2f ms", t * 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.2f s", t);
  return buf;
}

std::string label(const StudyRun& r) {
  std::ostringstream s;
  s << r.integrator << " " << r.setting << " " << std::setprecision(3) << r.value;
  return s.str();
}

std::string vector_text(const VecX& v) {
  std::ostringstream s;
  s << std::setprecision(6) << "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s << (i ? ", " : "") << v[i];
  return s.str() + "]";
}

// What was timed, where: the CPU, the cores, the compiler and the build.
std::string machine() {
  std::ifstream cpu("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(cpu, line))
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  std::ostringstream s;
  s << model << ", " << std::thread::hardware_concurrency() << " cores; build " FEMDYN_BUILD_TYPE
    << " ("
    << "g++ " << __VERSION__ << ")";
  return s.str();
}

std::string today() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", std::gmtime(&t));
  return buf;
}

std::string csv_text(const StudyReport& rep) {
  std::ostringstream s;
  s << std::setprecision(10)
    << "engine,integrator,setting,value,error,final_error,energy_drift,wall_time,repeats,"
       "rhs_evals,steps,ok,resolved,failure\n";
  for (const StudyRun& r : rep.runs) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    std::replace(failure.begin(), failure.end(), '"', '\'');
    s << r.engine << "," << r.integrator << "," << r.setting << "," << r.value << "," << r.error
      << "," << r.final_error << "," << r.energy_drift << "," << r.wall_time << ","
      << r.times.size() << "," << r.rhs_evals << "," << r.steps << "," << r.ok << "," << r.resolved
      << ",\"" << failure << "\"\n";
  }
  return s.str();
}

// gnuplot script with the data inline: one line per engine and integrator, femdyn solid,
// Simbody dashed. It writes study.png, or the file named by `gnuplot -e "out='…'"`.
std::string gnuplot_text(const StudyReport& rep) {
  std::ostringstream s, plots;
  s << std::setprecision(10) << "# femdyn study: " << rep.model << " (generated; gnuplot "
    << "study.gp)\nset terminal pngcairo size 1000,650 font 'sans,11'\n"
    << "if (!exists('out')) out = 'study.png'\nset output out\nset logscale xy\nset format x "
       "'10^{%L}'\nset format y '10^{%L}'\n"
    << "set xlabel 'wall time (s)'\nset ylabel 'max state error ‖(θ, θ̇) − reference‖∞'\n"
    << "set title 'Work-precision: " << rep.model << ", t = 0…" << rep.t_end << " s'\n"
    << "set grid\nset key outside right top\n";
  // Distinct colours: femdyn's in warm, Simbody's in cool tones.
  const char* femdyn_colour[] = {"#d62728", "#ff7f0e", "#8c564b", "#e377c2", "#bcbd22"};
  const char* simbody_colour[] = {"#1f77b4", "#2ca02c", "#17becf", "#9467bd", "#7f7f7f", "#393b79"};
  int block = 0, nf = 0, ns = 0;
  std::vector<std::string> done;
  for (const StudyRun& first : rep.runs) {
    const std::string key = first.engine + " " + first.integrator;
    if (std::find(done.begin(), done.end(), key) != done.end()) continue;
    done.push_back(key);
    std::ostringstream data;
    int points = 0;
    for (const StudyRun& r : rep.runs)
      if (r.engine == first.engine && r.integrator == first.integrator && r.resolved) {
        data << r.wall_time << " " << r.error << "\n";
        ++points;
      }
    if (points == 0) continue;
    s << "$d" << block << " << EOD\n" << data.str() << "EOD\n";
    plots << (block ? ", \\\n     " : "plot ") << "$d" << block << " using 1:2 with linespoints "
          << (first.engine == "femdyn"
                  ? "lw 2 pt 7 dt 1 lc rgb '" + std::string(femdyn_colour[nf++ % 5])
                  : "lw 1.5 pt 6 dt 2 lc rgb '" + std::string(simbody_colour[ns++ % 6]))
          << "' title '" << key << "'";
    ++block;
  }
  s << plots.str() << "\n";
  return s.str();
}

std::string markdown_text(const StudyReport& rep, const std::string& command) {
  std::ostringstream s;
  s << "# Work-precision: " << rep.model << "\n\n"
    << "Generated by `" << command << "` on " << today() << ". Machine: " << machine()
    << "; Simbody 3.7 (Debian).\n\n"
    << rep.n << " coordinates, t = 0…" << rep.t_end << " s from q0 = " << vector_text(rep.q0)
    << ", q̇0 = " << vector_text(rep.qd0) << ". Error: the largest ‖(θ, θ̇) − reference‖∞ "
    << "over the sample times (rad and rad/s, or m and m/s). Reference: " << rep.reference_method
    << "; its estimated error " << sci(rep.reference_error) << ", so errors below "
    << sci(rep.resolution) << " are not resolved and left out. Wall time: "
    << "the integration alone, median of up to 5 runs when a run is under 50 ms.\n\n"
    << "| target error | fastest femdyn | wall time | fastest Simbody | wall time | "
       "Simbody / femdyn |\n|---|---|---|---|---|---|\n";
  for (double target : {1e-3, 1e-6, 1e-9}) {
    const StudyRun* f = validation::fastest(rep, "femdyn", target);
    const StudyRun* b = validation::fastest(rep, "Simbody", target);
    s << "| " << format_number(target, "%.0e") << " | "
      << (f ? label(*f) + " (error " + sci(f->error) + ")" : "none reached it") << " | "
      << (f ? seconds(f->wall_time) : "—") << " | "
      << (b ? label(*b) + " (error " + sci(b->error) + ")" : "none reached it") << " | "
      << (b ? seconds(b->wall_time) : "—") << " | "
      << (f && b ? std::to_string(b->wall_time / f->wall_time).substr(0, 5) : "—") << " |\n";
  }
  if (rep.resolution > 1e-9)  // the smallest target cannot be resolved
    s << "\nA target below " << sci(rep.resolution) << " cannot be told apart from the "
      << "reference's own error here.\n";
  s << "\n![error against wall time](study.png)\n\n";
  for (const std::string& n : rep.notes) s << "Note: " << n << "\n\n";
  s << "Every run ("
    << (rep.conservative ? "the model is conservative: energy drift is "
                           "max |E(t) − E(0)|"
                         : "the model is not conservative: the energy column "
                           "is max |E(t) − E(0)|, not a drift")
    << "):\n\n| engine | integrator | setting | error | wall time | evaluations | steps | energy "
       "change (J) | note |\n|---|---|---|---|---|---|---|---|---|\n";
  for (const StudyRun& r : rep.runs)
    s << "| " << r.engine << " | " << r.integrator << " | " << r.setting << " "
      << std::setprecision(3) << r.value << " | " << (r.ok ? sci(r.error) : "—") << " | "
      << seconds(r.wall_time) << " | " << r.rhs_evals << " | " << r.steps << " | "
      << (r.ok ? sci(r.energy_drift) : "—") << " | "
      << (!r.ok        ? "failed: " + r.failure.substr(0, 90)
          : r.resolved ? ""
                       : "below resolution")
      << " |\n";
  return s.str();
}

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

}  // namespace

int cmd_study(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "quick", "force"},
                            {"gravity", "t-end", "out", "q0", "qd0"});
  if (a.has("help")) {
    std::cout << kHelp;
    return 0;
  }
#ifndef NDEBUG
  throw CliError("refusing to time a Debug build (build type " FEMDYN_BUILD_TYPE
                 "): rebuild with -DCMAKE_BUILD_TYPE=Release");
#endif
  const Model m = load(a);
  validation::StudyOptions o;
  o.quick = a.has("quick");
  o.t_end = number_option(a, "t-end", o.quick ? 0.5 : 1.0);
  if (!(o.t_end > 0) || o.t_end > 100) throw CliError("--t-end expects a time in (0, 100] s");
  std::mt19937 rng(1);
  o.q0 = a.has("q0") ? state_vector(a, "q0", m) : random_posture(m, rng);
  o.qd0 = a.has("qd0") ? state_vector(a, "qd0", m) : random_uniform(m.n(), 1.0, rng);

  // Outputs: checked before any work; each file appears whole.
  const fs::path dir = a.has("out") ? fs::path(a.options.at("out")) : fs::path("study");
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir))
    throw CliError("--out " + dir.string() + ": cannot create the directory");
  for (const char* f : {"study.csv", "study.gp", "study.png", "study.md"})
    if (fs::exists(dir / f) && !a.has("force"))
      throw CliError((dir / f).string() + ": exists (use --force to replace it)");

  std::string command = "femdyn study " + a.positional[0];
  for (int i = 3; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--force") continue;
    if (arg == "--out" && i + 1 < argc) {
      ++i;
      continue;
    }
    command += " " + arg;
  }
  const bool tty = isatty(STDERR_FILENO) == 1;
  const StudyReport rep = validation::run_study(m, o, [tty](const std::string& line) {
    if (tty) std::cerr << "  " << line << "\n";
  });

  const auto write = [&](const char* name, const std::string& text) {
    AtomicFile f((dir / name).string(), true);
    f.stream() << text;
    f.commit();
  };
  write("study.csv", csv_text(rep));
  write("study.gp", gnuplot_text(rep));
  // gnuplot renders into a temporary name, renamed when it succeeded.
  const bool plotted = run_gnuplot(dir, ".study.png.tmp");
  if (plotted) fs::rename(dir / ".study.png.tmp", dir / "study.png", ec);
  fs::remove(dir / ".study.png.tmp", ec);
  const std::string md = markdown_text(rep, command);
  write("study.md", md);
  if (!plotted)
    std::cerr << "femdyn study: warning: gnuplot failed or is missing (apt install gnuplot-nox); "
              << (dir / "study.gp").string() << " is written, study.png is not\n";

  // The summary table on stdout.
  std::cout << "model: " << rep.model << " (" << rep.n << " coordinates), t = 0…" << rep.t_end
            << " s, " << rep.runs.size() << " runs\nreference: " << rep.reference_method
            << ", estimated error " << sci(rep.reference_error) << "\n";
  std::istringstream lines(md);
  std::string line;
  while (std::getline(lines, line))
    if (line.rfind("| target", 0) == 0 || line.rfind("| 1e-", 0) == 0) std::cout << line << "\n";
  std::cout << "wrote " << (dir / "study.csv").string() << ", study.md, study.gp"
            << (plotted ? ", study.png" : "") << "\n";
  return 0;
}

}  // namespace femdyn::cli
