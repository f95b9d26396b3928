// femdyn study end to end (validation/study.hpp, cli/study.cpp): the files it writes, its JSON
// report, the sampling both engines share (Simbody's integrators interpolate like femdyn's),
// the timed repeats after a warm-up, the error's scales, the legend grouped by engine, the
// machine and its load; and the twin's two ways of sampling a trajectory.
#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sstream>

#include "core/kinematics/sampling.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "validation/study.hpp"
#include "validation/validate.hpp"

using namespace femdyn;
using namespace femdyn::test;
namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

// study's stdout alone (stderr dropped): the JSON report with --json.
Run study(const std::string& args) {
  return run_shell("{ " + std::string(FEMDYN_BINARY) + " study " + args + " 2>/dev/null; }");
}

}  // namespace

TEST_CASE("study: a quick work-precision run writes the CSV, plot, summary and JSON report",
          "[study]") {
  Scratch s("study");
  const std::string dir = s / "out";
#ifndef NDEBUG  // a build with asserts (Debug, tools/sanitize.sh): study refuses to time it
  const Run refused = run("study " + model_path("pendulum.json") + " --quick --out " + dir);
  CHECK(refused.code == 2);
  CHECK_THAT(refused.out, Catch::StartsWith("femdyn study: refusing to time a Debug build ("));
  CHECK_FALSE(fs::exists(dir));
  return;
#endif
  Run r = study(model_path("spatial_double_pendulum.json") + " --quick --json --out " + dir);
  INFO(r.out.substr(0, 2000));
  REQUIRE(r.code == 0);
  const Json j = Json::parse(r.out);  // stdout is the one JSON object
  for (const char* f : {"study.csv", "study.md", "study.gp", "study.png"})
    CHECK(fs::file_size(fs::path(dir) / f) > 0);
  CHECK(std::distance(fs::directory_iterator(dir), {}) == 4);  // no temporary left behind

  CHECK(j["model"] == "spatial double pendulum");
  CHECK(j["n"] == 2);
  CHECK(j["t_end"] == 0.5);
  CHECK(j["samples"] == 20);
  CHECK(j["interpolate"] == true);
  CHECK(j["formulation"]["same"] == true);
  CHECK(j["command"] == "femdyn study " + model_path("spatial_double_pendulum.json") + " --quick");

  // The machine: the CPU, its cores and the load average at the start and the end.
  const Json& machine = j["machine"];
  CHECK_FALSE(machine["cpu"].get<std::string>().empty());
  CHECK(machine["cores"].get<int>() >= 1);
  CHECK(machine["load_start"].size() == 3);
  CHECK(machine["load_end"].size() == 3);
  CHECK(machine["build"] == "Release");

  // The error's scales: the reference's largest angle and angular rate, in rad and rad/s.
  const Json& scales = j["error"]["scales"];
  REQUIRE(scales.size() == 2);
  CHECK(scales[0]["unit"] == "rad");
  CHECK(scales[1]["unit"] == "rad/s");
  CHECK(scales[0]["size"].get<double>() > 0.1);
  CHECK(scales[1]["size"].get<double>() > 0.1);

  // Every run: a warm-up, then three timed runs (--quick) whose median is the wall time; the
  // relative error is the absolute one over the scales.
  std::set<std::string> integrators;
  std::map<double, const Json*> merson;  // RungeKuttaMerson by accuracy
  double smallest_resolved = INFINITY;
  const double reference_error = j["reference"]["error"];
  for (const Json& run : j["runs"]) {
    integrators.insert(run["engine"].get<std::string>() + " " +
                       run["integrator"].get<std::string>());
    if (run["integrator"] == "RungeKuttaMerson") merson[run["value"].get<double>()] = &run;
    if (!run["ok"].get<bool>()) continue;
    std::vector<double> t = run["times"];
    INFO(run.dump());
    REQUIRE(t.size() == 3);
    std::sort(t.begin(), t.end());
    CHECK(run["wall_time"].get<double>() == t[1]);
    CHECK(run["warm_up_time"].get<double>() > 0);
    const double relative =
        std::max(run["position_error"].get<double>() / scales[0]["size"].get<double>(),
                 run["rate_error"].get<double>() / scales[1]["size"].get<double>());
    CHECK(run["error"].get<double>() == Approx(relative).epsilon(1e-12));
    if (run["resolved"].get<bool>())
      smallest_resolved = std::min(smallest_resolved, run["error"].get<double>());
    CHECK(run["resolved"].get<bool>() == (run["error"].get<double>() >= 100 * reference_error));
  }
  for (const char* name : {"femdyn rk4", "femdyn euler", "femdyn dopri", "femdyn bdf",
                           "Simbody RungeKuttaMerson", "Simbody RungeKutta3", "Simbody CPodes"})
    CHECK(integrators.count(name) == 1);
  // The reference's own error is at least 100x below every error plotted.
  INFO("reference error " << reference_error << ", smallest resolved error " << smallest_resolved);
  CHECK(reference_error < 1e-11);
  CHECK(j["reference"]["resolution"].get<double>() == Approx(100 * reference_error));
  CHECK(100 * reference_error <= smallest_resolved);

  // Simbody interpolates: RungeKuttaMerson at accuracies 1e-2 … 1e-5 takes more steps and
  // makes a smaller error at each, and at 1e-2 fewer steps than the 20 samples (landing on
  // every sample, it took 21 steps with the same error at all four).
  std::vector<const Json*> loose;
  for (double a : {1e-2, 1e-3, 1e-4, 1e-5}) {
    const auto it = merson.lower_bound(a * (1 - 1e-9));
    REQUIRE(it != merson.end());
    REQUIRE(it->first == Approx(a));
    loose.push_back(it->second);
  }
  CHECK((*loose[0])["steps"].get<long>() < 20);
  for (std::size_t i = 1; i < loose.size(); ++i) {
    INFO((*loose[i - 1]).dump() << "\n" << (*loose[i]).dump());
    CHECK((*loose[i])["steps"].get<long>() > (*loose[i - 1])["steps"].get<long>());
    CHECK((*loose[i])["error"].get<double>() < (*loose[i - 1])["error"].get<double>());
  }

  // The targets, in the JSON and in study.md, with the ratio where both engines reached them.
  REQUIRE(j["targets"].size() == 3);
  const Json& t3 = j["targets"][0];
  CHECK(t3["target"] == 1e-3);
  REQUIRE(t3["femdyn"].is_object());
  REQUIRE(t3["simbody"].is_object());
  CHECK(t3["ratio"].get<double>() ==
        Approx(t3["simbody"]["wall_time"].get<double>() / t3["femdyn"]["wall_time"].get<double>()));
  const std::string md = read_file(fs::path(dir) / "study.md");
  for (const char* target : {"| 1e-03 |", "| 1e-06 |", "| 1e-09 |"})
    CHECK_THAT(md, Catch::Contains(target));
  CHECK_THAT(md, Catch::Contains("both engines step freely and interpolate at the samples") &&
                     Catch::Contains("relative state error") && Catch::Contains("largest angle ") &&
                     Catch::Contains(" rad/s") && Catch::Contains("load average (1, 5, 15 min) ") &&
                     Catch::Contains("then the median of 3 timed runs") &&
                     !Catch::Contains("not the same formulation"));

  // The CSV: comment lines first (sampling, error, reference, machine with its load), then
  // one row per run of the JSON, the same numbers.
  std::ifstream csv(fs::path(dir) / "study.csv");
  std::string line, comments;
  while (std::getline(csv, line) && line.rfind("#", 0) == 0) comments += line + "\n";
  CHECK_THAT(comments, Catch::Contains("# sampling: both engines step freely") &&
                           Catch::Contains("# error: relative state error") &&
                           Catch::Contains("# reference: ") && Catch::Contains("# machine: ") &&
                           Catch::Contains(" cores; load average (1, 5, 15 min) "));
  CHECK(line ==
        "engine,integrator,setting,value,error,position_error,rate_error,final_error,"
        "energy_drift,wall_time,repeats,warm_up_time,wall_time_min,wall_time_max,rhs_evals,steps,"
        "ok,resolved,failure");
  std::size_t rows = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    std::string cell;
    while (std::getline(l, cell, ',')) cells.push_back(cell);
    REQUIRE(cells.size() >= 18);
    REQUIRE(rows < j["runs"].size());
    const Json& run = j["runs"][rows++];
    CHECK(cells[0] == run["engine"]);
    CHECK(cells[1] == run["integrator"]);
    CHECK(std::stod(cells[4]) == Approx(run["error"].get<double>()).epsilon(1e-9));
    CHECK(std::stod(cells[9]) == Approx(run["wall_time"].get<double>()).epsilon(1e-9));
    CHECK(std::stol(cells[15]) == run["steps"].get<long>());
  }
  CHECK(rows == j["runs"].size());

  // The plot: axes with their meaning and units; the key femdyn's curves, then Simbody's.
  const std::string gp = read_file(fs::path(dir) / "study.gp");
  CHECK_THAT(gp, Catch::Contains("set ylabel \"relative state error") &&
                     Catch::Contains("θ in rad, θ̇ in rad/s") &&
                     Catch::Contains("set xlabel \"wall time (s)") &&
                     Catch::Contains("both engines interpolate at the 20 samples"));
  const auto at = [&](const std::string& text) {
    const auto p = gp.find(text);
    INFO(text);
    CHECK(p != std::string::npos);
    return p;
  };
  const auto femdyn_key = at("title '{/:Bold femdyn} (solid)'"),
             simbody_key = at("title '{/:Bold Simbody} (dashed)'");
  CHECK(femdyn_key < simbody_key);
  for (const char* f : {"title 'rk4'", "title 'euler'", "title 'dopri'", "title 'bdf'"}) {
    CHECK(at(f) > femdyn_key);
    CHECK(at(f) < simbody_key);
  }
  for (const char* b : {"title 'RungeKuttaMerson'", "title 'CPodes'"}) CHECK(at(b) > simbody_key);

  // Existing outputs are kept without --force.
  r = run("study " + model_path("pendulum.json") + " --quick --out " + dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.out, Catch::Contains("study.csv: exists (use --force to replace it)"));
}

// The twin's two ways of sampling (TwinSampling): landing on every sample, RungeKuttaMerson
// takes at least a step per sample and the same steps at every loose accuracy; interpolating,
// it takes fewer steps than samples at 1e-2, more at each tighter accuracy, and its samples
// stay within the accuracy's reach of a tight run.
TEST_CASE("the twin samples a trajectory by landing on each sample or by interpolation",
          "[study][validation]") {
  const Model m = load_model(model_path("spatial_double_pendulum.json"));
  validation::SimbodyTwin twin(validation::twin_model(m));
  REQUIRE(twin.can_simulate());
  VecX q0(2), qd0(2);
  q0 << 0.7, -0.4;
  qd0 << 1.5, -2.0;
  std::vector<double> times;
  for (int i = 0; i <= 20; ++i) times.push_back(0.025 * i);
  using validation::SimbodyIntegrator;
  using validation::TwinSampling;
  const auto tight =
      twin.simulate(q0, qd0, times, 1e-12, SimbodyIntegrator::RungeKuttaMerson).samples;
  REQUIRE(tight.size() == times.size());
  const auto error = [&](const validation::TwinRun& r) {
    double e = 0;
    for (std::size_t k = 0; k < times.size(); ++k)
      e = std::max({e, (r.samples[k].theta - tight[k].theta).lpNorm<Eigen::Infinity>(),
                    (r.samples[k].theta_dot - tight[k].theta_dot).lpNorm<Eigen::Infinity>()});
    return e;
  };
  long last_steps = 0;
  double last_error = INFINITY;
  for (double accuracy : {1e-2, 1e-3, 1e-4, 1e-5}) {
    const validation::TwinRun land = twin.simulate(
        q0, qd0, times, accuracy, SimbodyIntegrator::RungeKuttaMerson, TwinSampling::StepToEach);
    const validation::TwinRun free = twin.simulate(
        q0, qd0, times, accuracy, SimbodyIntegrator::RungeKuttaMerson, TwinSampling::Interpolate);
    INFO("accuracy " << accuracy << ": landing " << land.stats.steps << " steps, error "
                     << error(land) << "; interpolating " << free.stats.steps << " steps, error "
                     << error(free) << " " << free.stats.failure);
    REQUIRE(land.stats.ok);
    REQUIRE(free.stats.ok);
    REQUIRE(free.samples.size() == times.size());
    for (std::size_t k = 0; k < times.size(); ++k) CHECK(free.samples[k].t == times[k]);
    CHECK(land.stats.steps >= 20);
    CHECK(free.stats.steps > last_steps);
    CHECK(error(free) < last_error);
    CHECK(error(free) < 200 * accuracy);
    if (accuracy == 1e-2) CHECK(free.stats.steps < 20);
    last_steps = free.stats.steps;
    last_error = error(free);
  }
}

TEST_CASE("study on a floating base measures quaternions on their manifold", "[study][joints]") {
#ifndef NDEBUG
  return;  // (study refuses to time a build with asserts; see above)
#endif
  // A free base carrying a ball-jointed arm: the error of a quaternion is the rotation vector
  // between the two, so rk4's error falls as dt⁴ (16x per halving, here at least 10x) and
  // Simbody's twin (Free and Ball mobilizers, its own quaternions) is measured the same way.
  Scratch s("study_floating");
  std::ofstream(s / "floating.json") << R"({"name": "floating two-link", "gravity": [0, 0, 0],
    "bodies": [{"name": "base", "parent": "world", "joint": {"type": "free"},
      "elements": [{"type": "rigid_body", "mass": 10, "com": [0, 0, 0],
                    "inertia": {"ixx": 1, "iyy": 1.2, "izz": 0.8}}]},
     {"name": "arm", "parent": "base",
      "joint": {"type": "spherical", "origin": {"xyz": [0.5, 0, 0]}},
      "elements": [{"type": "rigid_body", "mass": 2, "com": [0.3, 0, 0],
                    "inertia": {"ixx": 0.01, "iyy": 0.05, "izz": 0.05}}]}]})";
  const Run r = study(s / "floating.json" + " --quick --json --out " + (s / "out"));
  INFO(r.out.substr(0, 2000));
  REQUIRE(r.code == 0);
  const Json j = Json::parse(r.out);
  std::set<std::string> units;
  for (const Json& scale : j["error"]["scales"]) units.insert(scale["unit"]);
  CHECK(units == std::set<std::string>{"rad", "rad/s", "m", "m/s"});
  std::map<double, double> rk4;  // dt -> error
  double simbody_best = INFINITY;
  for (const Json& run : j["runs"]) {
    if (!run["ok"].get<bool>()) continue;
    if (run["integrator"] == "rk4") rk4[run["value"].get<double>()] = run["error"];
    if (run["engine"] == "Simbody")
      simbody_best = std::min(simbody_best, run["error"].get<double>());
  }
  REQUIRE(rk4.size() >= 3);
  auto it = rk4.rbegin();  // the two largest steps (the finest reach round-off)
  const double coarsest = it->second, next = (++it)->second;
  CHECK(coarsest > 10 * next);
  CHECK(simbody_best < 1e-6);  // Simbody's tightest accuracy tracks the same reference
}

// Bounded work: the reference is estimated from a probe of its method and refused beyond
// --budget, in one line with the --t-end that fits; the estimate is checked against the
// reference runs timed here, on a model whose probe covers only half of the run.
TEST_CASE("study estimates its reference and refuses it beyond the budget", "[study]") {
#ifndef NDEBUG
  return;  // (study refuses to time a build with asserts; see above)
#endif
  Scratch s("study_budget");
  const std::string model = model_path("andrews.json");
  const Run refused = run("study " + model + " --quick --budget 0.01 --out " + s / "refused");
  CHECK(refused.code == 1);
  CHECK(std::count(refused.out.begin(), refused.out.end(), '\n') == 1);
  CHECK_THAT(refused.out,
             Catch::StartsWith("femdyn study: " + model +
                               ": the reference solution (dopri at "
                               "rtol 1e-14, then 1e-13, over 0.5 s) would take about ") &&
                 Catch::Contains("beyond the budget of 0.01 s: use --t-end ") &&
                 Catch::Contains(" or raise --budget"));
  CHECK_FALSE(fs::exists(fs::path(s / "refused") / "study.csv"));

  // The estimate against the two reference runs timed here (dopri landing on the 20 samples at
  // rtol = atol 1e-14, then 1e-13) from the same state, over --quick's 0.5 s.
  const Model m = load_model(model);
  validation::StudyOptions o;
  o.t_end = 0.5;
  std::mt19937 rng(1);
  o.q0 = random_posture(m, rng);
  o.qd0 = random_rates(m, 1.0, rng);
  const validation::StudyEstimate e = validation::estimate_study(m, o);
  INFO("probe " << e.probe_t << " s in " << e.probe_wall << " s; estimate " << e.reference);
  CHECK(e.probe_wall == Approx(validation::StudyEstimate::kProbeSeconds).margin(0.05));
  CHECK(e.probe_t < o.t_end);  // the probe stopped inside the run
  double measured = 0;
  for (double rtol : {1e-14, 1e-13}) {
    auto integ = make_integrator(
        m, {.kind = IntegratorKind::Dopri,
            .adaptive = {
                .rtol = rtol, .atol = rtol, .max_steps = 100'000'000, .stop_at_outputs = true}});
    integ->reset(0, o.q0, o.qd0, o.t_end);
    for (int k = 1; k <= 20; ++k) REQUIRE(integ->advance_to(o.t_end * k / 20).ok);
    measured += integ->stats().wall_time;
  }
  INFO("measured " << measured << " s");
  CHECK(e.reference / measured > 0.5);
  CHECK(e.reference / measured < 2);
}

// A model with loop constraints: study starts both engines from one assembled state and
// Simbody integrates the closed mechanism, so its error falls with its accuracy (against the
// tree without its constraints it stayed at 4e-2).
TEST_CASE("study closes a model's loop constraints in both engines", "[study][loops]") {
#ifndef NDEBUG
  return;  // (study refuses to time a build with asserts; see above)
#endif
  Scratch s("study_loop");
  const Run r = study(model_path("finger_fourbar_loop.json") + " --quick --json --out " + s / "o");
  REQUIRE(r.code == 0);
  const Json j = Json::parse(r.out);
  double best = INFINITY;
  for (const Json& run : j["runs"])
    if (run["integrator"] == "RungeKuttaMerson" && run["ok"] == true)
      best = std::min(best, run["error"].get<double>());
  CHECK(best < 1e-5);
  bool noted = false;
  for (const Json& n : j["notes"])
    noted = noted || n.get<std::string>().rfind("loop constraints: both engines", 0) == 0;
  CHECK(noted);
}
