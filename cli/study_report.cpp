// study.csv, study.gp, study.md and the JSON report of femdyn study (cli/study_report.hpp).
#include "cli/study_report.hpp"

#include <algorithm>
#include <ctime>
#include <iomanip>
#include <sstream>

#include "io/csv.hpp"
#include "io/output.hpp"

#ifndef FEMDYN_BUILD_TYPE
#define FEMDYN_BUILD_TYPE "unknown"
#endif

namespace femdyn::cli {

using validation::StudyReport;
using validation::StudyRun;

namespace {

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

std::string compiler() { return std::string("g++ ") + __VERSION__; }

std::string load_text(const std::vector<double>& v) {
  if (v.size() != 3) return "unknown";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f %.2f %.2f", v[0], v[1], v[2]);
  return buf;
}

// What was timed, where: the CPU, the cores, the load, the compiler and the build.
std::string machine_text(const StudyReport& rep) {
  std::ostringstream s;
  s << rep.machine.cpu << ", " << rep.machine.cores << " cores; load average (1, 5, 15 min) "
    << load_text(rep.machine.load_start) << " at the start, " << load_text(rep.machine.load_end)
    << " at the end; build " FEMDYN_BUILD_TYPE " (" << compiler() << ")";
  return s.str();
}

std::string today() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d", std::gmtime(&t));
  return buf;
}

// The units of the absolute position and rate errors: "rad", "rad/s", or with prismatic
// joints "rad or m", "rad/s or m/s".
std::pair<std::string, std::string> units(const StudyReport& rep) {
  std::string position, rate;
  for (const StudyReport::Scale& g : rep.scales) {
    std::string& u = (g.unit == "rad" || g.unit == "m") ? position : rate;
    u += (u.empty() ? "" : " or ") + g.unit;
  }
  return {position, rate};
}

// "the largest angle 1.48 rad, the largest angular rate 5.2 rad/s"
std::string scales_text(const StudyReport& rep) {
  std::string s;
  for (const StudyReport::Scale& g : rep.scales)
    s += (s.empty() ? "" : ", ") + std::string("largest ") + g.quantity + " " +
         format_number(g.size, "%.3g") + " " + g.unit;
  return s;
}

// "wall time (s): median of 5 timed runs after a warm-up (3 for runs of 50 ms or longer)"
std::string xlabel(const StudyReport& rep) {
  std::ostringstream s;
  s << "wall time (s): median of " << rep.timed_repeats << " timed runs after a warm-up";
  if (rep.timed_repeats != rep.timed_repeats_long)
    s << " (" << rep.timed_repeats_long << " for runs of 50 ms or longer)";
  return s.str();
}

struct Target {
  double target;
  const StudyRun *femdyn, *simbody;
};
std::vector<Target> targets(const StudyReport& rep) {
  std::vector<Target> out;
  for (double t : {1e-3, 1e-6, 1e-9})
    out.push_back(
        {t, validation::fastest(rep, "femdyn", t), validation::fastest(rep, "Simbody", t)});
  return out;
}

// Text that goes into a comment line: no line breaks.
std::string comment(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

// A string as gnuplot reads it between double quotes.
std::string gp_string(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string ratio_text(const StudyReport& rep, const Target& t) {
  if (!t.femdyn || !t.simbody) return "—";
  const std::string ratio = format_number(t.simbody->wall_time / t.femdyn->wall_time, "%.3g");
  return rep.same_formulation ? ratio : ratio + " (" + formulation_text(rep) + ")";
}

nlohmann::ordered_json vector_json(const VecX& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

nlohmann::ordered_json run_json(const StudyRun& r) {
  return {{"engine", r.engine},
          {"integrator", r.integrator},
          {"setting", r.setting},
          {"value", r.value},
          {"ok", r.ok},
          {"resolved", r.resolved},
          {"error", r.error},
          {"position_error", r.position_error},
          {"rate_error", r.rate_error},
          {"final_error", r.final_error},
          {"energy_drift", r.energy_drift},
          {"wall_time", r.wall_time},
          {"warm_up_time", r.warm_up_time},
          {"times", r.times},
          {"steps", r.steps},
          {"rhs_evals", r.rhs_evals},
          {"failure", r.failure}};
}

}  // namespace

std::string formulation_text(const StudyReport& rep) {
  return "femdyn: " + rep.femdyn_formulation + "; Simbody: " + rep.simbody_formulation +
         " — not the same formulation";
}

std::string timing_text(const StudyReport& rep) {
  std::ostringstream s;
  s << "each run once as a warm-up (not counted), then the median of ";
  if (rep.timed_repeats == rep.timed_repeats_long)
    s << rep.timed_repeats << " timed runs";
  else
    s << rep.timed_repeats << " timed runs (" << rep.timed_repeats_long
      << " for runs of 50 ms or longer)";
  s << ", femdyn and Simbody alternating";
  return s.str();
}

std::string sampling_short(const StudyReport& rep) {
  return rep.interpolate
             ? "both engines interpolate at the " + std::to_string(rep.samples) +
                   " samples (dense output; rk4, euler land on them)"
             : "both engines land on each of the " + std::to_string(rep.samples) + " samples";
}

std::string csv_text(const StudyReport& rep, const std::string& command) {
  const auto [position_unit, rate_unit] = units(rep);
  std::ostringstream s;
  s << "# femdyn study: " << comment(rep.model) << ", " << rep.n << " coordinates, t = 0…"
    << rep.t_end << " s, " << rep.samples << " samples; " << comment(command) << "\n"
    << "# sampling: " << rep.sampling << "\n"
    << "# error: relative state error (dimensionless), the largest |Δθ| over the samples and "
       "joints over the reference's largest |θ|, or the same for the rates, whichever is "
       "larger; "
    << scales_text(rep) << "; position_error in " << position_unit << ", rate_error in "
    << rate_unit << "\n"
    << "# reference: " << rep.reference_method << "; estimated error "
    << format_sci(rep.reference_error) << "; resolution " << format_sci(rep.resolution) << "\n";
  if (!rep.same_formulation) s << "# formulation: " << formulation_text(rep) << "\n";
  s << "# wall_time: median of the timed runs (s), " << timing_text(rep) << "\n"
    << "# machine: " << comment(machine_text(rep)) << "\n"
    << std::setprecision(10)
    << "engine,integrator,setting,value,error,position_error,rate_error,final_error,energy_drift,"
       "wall_time,repeats,warm_up_time,wall_time_min,wall_time_max,rhs_evals,steps,ok,resolved,"
       "failure\n";
  for (const StudyRun& r : rep.runs) {
    std::string failure = r.failure;
    for (char c : {',', '#', '\n'}) std::replace(failure.begin(), failure.end(), c, ';');
    std::replace(failure.begin(), failure.end(), '"', '\'');
    const auto [lo, hi] = std::minmax_element(r.times.begin(), r.times.end());
    s << csv_field(r.engine) << "," << csv_field(r.integrator) << "," << csv_field(r.setting) << ","
      << r.value << "," << r.error << "," << r.position_error << "," << r.rate_error << ","
      << r.final_error << "," << r.energy_drift << "," << r.wall_time << "," << r.times.size()
      << "," << r.warm_up_time << "," << (r.times.empty() ? 0 : *lo) << ","
      << (r.times.empty() ? 0 : *hi) << "," << r.rhs_evals << "," << r.steps << "," << r.ok << ","
      << r.resolved << ",\"" << failure << "\"\n";
  }
  return s.str();
}

// gnuplot script with the data inline: one line per engine and integrator, femdyn's first
// (solid, warm tones) under a "femdyn" heading, then Simbody's (dashed, cool tones) under
// "Simbody". It writes study.png, or the file named by `gnuplot -e "out='…'"`.
std::string gnuplot_text(const StudyReport& rep) {
  std::ostringstream s, plots;
  std::string title = "Work-precision: " + rep.model + ", t = 0…" + format_short(rep.t_end) +
                      " s\n" + sampling_short(rep);
  if (!rep.same_formulation) title += "\n" + formulation_text(rep);
  s << std::setprecision(10) << "# femdyn study: " << comment(rep.model) << " (generated; gnuplot "
    << "study.gp)\nset terminal pngcairo size 1100,700 font 'sans,11'\n"
    << "if (!exists('out')) out = 'study.png'\nset output out\nset logscale xy\nset format x "
       "'10^{%L}'\nset format y '10^{%L}'\n"
    << "set xlabel " << gp_string(xlabel(rep)) << " noenhanced\n"
    << "set ylabel "
    << gp_string("relative state error: max(|Δθ| / max|θ|, |Δθ̇| / max|θ̇|)   (θ in " +
                 units(rep).first + ", θ̇ in " + units(rep).second + ")")
    << " noenhanced\n"
    << "set title " << gp_string(title) << " noenhanced\n"
    << "set grid\nset key outside right top\n";
  // Distinct colours: femdyn's in warm, Simbody's in cool tones.
  const char* femdyn_colour[] = {"#d62728", "#ff7f0e", "#8c564b", "#e377c2", "#bcbd22"};
  const char* simbody_colour[] = {"#1f77b4", "#2ca02c", "#17becf", "#9467bd", "#7f7f7f", "#393b79"};
  int block = 0;
  for (const std::string engine : {"femdyn", "Simbody"}) {
    std::vector<std::string> done;
    int curves = 0;
    for (const StudyRun& first : rep.runs) {
      if (first.engine != engine ||
          std::find(done.begin(), done.end(), first.integrator) != done.end())
        continue;
      done.push_back(first.integrator);
      std::ostringstream data;
      int points = 0;
      for (const StudyRun& r : rep.runs)
        if (r.engine == engine && r.integrator == first.integrator && r.resolved) {
          data << r.wall_time << " " << r.error << "\n";
          ++points;
        }
      if (points == 0) continue;
      if (curves++ == 0)  // the engine's heading in the key
        plots << (block ? ", \\\n     keyentry with lines lt nodraw title ' ', \\\n     " : "plot ")
              << "keyentry with lines lt nodraw title '{/:Bold " << engine << "} ("
              << (engine == "femdyn" ? "solid" : "dashed") << ")'";
      s << "$d" << block << " << EOD\n" << data.str() << "EOD\n";
      plots << ", \\\n     $d" << block << " using 1:2 with linespoints "
            << (engine == "femdyn"
                    ? "lw 2 pt 7 dt 1 lc rgb '" + std::string(femdyn_colour[(curves - 1) % 5])
                    : "lw 1.5 pt 6 dt 2 lc rgb '" + std::string(simbody_colour[(curves - 1) % 6]))
            << "' title '" << first.integrator << "' noenhanced";
      ++block;
    }
  }
  s << plots.str() << "\n";
  return s.str();
}

std::string markdown_text(const StudyReport& rep, const std::string& command) {
  const auto [position_unit, rate_unit] = units(rep);
  std::ostringstream s;
  s << "# Work-precision: " << rep.model
    << (rep.interpolate ? "" : ", both engines landing on every sample") << "\n\n"
    << "Generated by `" << command << "` on " << today() << ". Machine: " << machine_text(rep)
    << "; Simbody 3.7 (Debian).\n\n"
    << rep.n << " coordinates, t = 0…" << rep.t_end << " s from q0 = " << vector_text(rep.q0)
    << ", q̇0 = " << vector_text(rep.qd0) << ", " << rep.samples << " sample times.\n\n"
    << "- **Sampling:** " << rep.sampling << ".\n"
    << "- **Error** (the y axis): the relative state error, dimensionless: the largest "
    << "|θ − θ_ref| over the samples and the joints divided by the reference's largest |θ|, or "
    << "the largest |θ̇ − θ̇_ref| divided by its largest |θ̇|, whichever is larger ("
    << scales_text(rep) << "). The absolute errors (" << position_unit << ", " << rate_unit
    << ") are in study.csv. Reference: " << rep.reference_method << "; its estimated error "
    << format_sci(rep.reference_error) << ", so errors below " << format_sci(rep.resolution)
    << " are not resolved and left out.\n"
    << "- **Wall time** (the x axis): the integration alone; " << timing_text(rep) << ".\n";
  if (!rep.same_formulation)
    s << "- **Formulation:** " << formulation_text(rep)
      << ": the ratios compare the two formulations, not the two engines on the same "
         "equations.\n";
  s << "\n| target error | fastest femdyn | wall time | fastest Simbody | wall time | "
       "Simbody / femdyn |\n|---|---|---|---|---|---|\n";
  for (const Target& t : targets(rep)) {
    const StudyRun *f = t.femdyn, *b = t.simbody;
    s << "| " << format_number(t.target, "%.0e") << " | "
      << (f ? label(*f) + " (error " + format_sci(f->error) + ")" : "none reached it") << " | "
      << (f ? seconds(f->wall_time) : "—") << " | "
      << (b ? label(*b) + " (error " + format_sci(b->error) + ")" : "none reached it") << " | "
      << (b ? seconds(b->wall_time) : "—") << " | " << ratio_text(rep, t) << " |\n";
  }
  if (rep.resolution > 1e-9)  // the smallest target cannot be resolved
    s << "\nA target below " << format_sci(rep.resolution) << " cannot be told apart from the "
      << "reference's own error here.\n";
  s << "\n![error against wall time](study.png)\n\n";
  for (const std::string& n : rep.notes) s << "Note: " << n << "\n\n";
  s << "Every run ("
    << (rep.conservative ? "the model is conservative: energy drift is "
                           "max |E(t) − E(0)|"
                         : "the model is not conservative: the energy column "
                           "is max |E(t) − E(0)|, not a drift")
    << "; wall time the median of the timed runs, with their range):\n\n"
    << "| engine | integrator | setting | error | max abs(Δθ) (" << position_unit
    << ") | max abs(Δθ̇) (" << rate_unit
    << ") | wall time | range | evaluations | steps | energy change (J) | note |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const StudyRun& r : rep.runs) {
    const auto [lo, hi] = std::minmax_element(r.times.begin(), r.times.end());
    s << "| " << r.engine << " | " << r.integrator << " | " << r.setting << " "
      << std::setprecision(3) << r.value << " | " << (r.ok ? format_sci(r.error) : "—") << " | "
      << (r.ok ? format_sci(r.position_error) : "—") << " | "
      << (r.ok ? format_sci(r.rate_error) : "—") << " | " << seconds(r.wall_time) << " | "
      << (r.times.size() > 1 ? seconds(*lo) + " – " + seconds(*hi) : "one run") << " | "
      << r.rhs_evals << " | " << r.steps << " | " << (r.ok ? format_sci(r.energy_drift) : "—")
      << " | "
      << (!r.ok        ? "failed: " + r.failure.substr(0, 90)
          : r.resolved ? ""
                       : "below resolution")
      << " |\n";
  }
  return s.str();
}

nlohmann::ordered_json report_json(const StudyReport& rep, const std::string& command,
                                   const validation::StudyOptions& o,
                                   const validation::StudyEstimate& e) {
  using J = nlohmann::ordered_json;
  J scales = J::array();
  for (const StudyReport::Scale& g : rep.scales)
    scales.push_back({{"quantity", g.quantity}, {"size", g.size}, {"unit", g.unit}});
  const auto [position_unit, rate_unit] = units(rep);
  J runs = J::array(), tgts = J::array();
  for (const StudyRun& r : rep.runs) runs.push_back(run_json(r));
  for (const Target& t : targets(rep)) {
    const auto brief = [](const StudyRun* r) -> J {
      if (!r) return nullptr;
      return {{"integrator", r->integrator},
              {"setting", r->setting},
              {"value", r->value},
              {"error", r->error},
              {"wall_time", r->wall_time}};
    };
    J ratio = nullptr;
    if (t.femdyn && t.simbody) ratio = t.simbody->wall_time / t.femdyn->wall_time;
    tgts.push_back({{"target", t.target},
                    {"femdyn", brief(t.femdyn)},
                    {"simbody", brief(t.simbody)},
                    {"ratio", ratio},
                    {"same_formulation", rep.same_formulation}});
  }
  return {{"model", rep.model},
          {"n", rep.n},
          {"t_end", rep.t_end},
          {"samples", rep.samples},
          {"estimate",
           {{"reference_s", e.reference},
            {"reference_measured_s", rep.reference_wall},
            {"probe_t", e.probe_t},
            {"probe_wall_s", e.probe_wall},
            {"budget_s", o.budget}}},
          {"q0", vector_json(rep.q0)},
          {"qd0", vector_json(rep.qd0)},
          {"interpolate", rep.interpolate},
          {"sampling", rep.sampling},
          {"conservative", rep.conservative},
          {"error",
           {{"definition",
             "relative state error (dimensionless): max over the samples of the largest "
             "|Δθ| over the largest reference |θ|, or the same for the rates, by group"},
            {"position_unit", position_unit},
            {"rate_unit", rate_unit},
            {"scales", scales}}},
          {"reference",
           {{"method", rep.reference_method},
            {"rtol", rep.reference_rtol},
            {"error", rep.reference_error},
            {"resolution", rep.resolution}}},
          {"formulation",
           {{"same", rep.same_formulation},
            {"femdyn", rep.femdyn_formulation},
            {"simbody", rep.simbody_formulation}}},
          {"timing",
           {{"warm_up", true},
            {"repeats", rep.timed_repeats},
            {"repeats_long", rep.timed_repeats_long},
            {"repeat_below", o.repeat_below}}},
          {"targets", tgts},
          {"runs", runs},
          {"notes", rep.notes},
          {"machine",
           {{"cpu", rep.machine.cpu},
            {"cores", rep.machine.cores},
            {"build", FEMDYN_BUILD_TYPE},
            {"compiler", compiler()},
            {"load_start", rep.machine.load_start},
            {"load_end", rep.machine.load_end}}},
          {"command", command},
          {"date", today()}};
}

}  // namespace femdyn::cli
