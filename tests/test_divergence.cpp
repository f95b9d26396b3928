// A run whose solution blows up fails as a divergence with its cause (sim/divergence.hpp),
// never as "ok" and never blamed on the model; runs that are merely inaccurate, falling or
// driven are not called diverged; fixed-step times lie on the grid t0 + k dt; a run that
// cannot finish is refused before it starts (docs/simulation.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sim/integrator.hpp"
#include "sim/recorded_run.hpp"
#include "sim/stability.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
namespace fs = std::filesystem;

namespace {

// An arm on a rail: a prismatic carriage, two 0.4 m links and a light tip link (its fast mode
// sets the step limit) under gravity.
constexpr const char* kRailArm = R"({"name": "rail arm", "gravity": [0, 0, -9.81], "bodies": [
  {"name": "cart", "parent": "world", "joint": {"name": "rail", "type": "prismatic",
   "axis": [1, 0, 0]}, "elements": [{"type": "lumped_point", "node": [0, 0, 0], "mass": 2.0}]},
  {"name": "l1", "parent": "cart", "joint": {"name": "j1", "type": "revolute", "axis": [0, 1, 0]},
   "elements": [{"type": "rigid_body", "mass": 1.0, "com": [0.2, 0, 0],
                 "inertia": {"ixx": 1e-3, "iyy": 0.014, "izz": 0.014}}]},
  {"name": "l2", "parent": "l1", "joint": {"name": "j2", "type": "revolute", "axis": [0, 1, 0],
   "origin": {"xyz": [0.4, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.2, 0, 0],
                 "inertia": {"ixx": 5e-4, "iyy": 0.007, "izz": 0.007}}]},
  {"name": "l3", "parent": "l2", "joint": {"name": "j3", "type": "revolute", "axis": [0, 1, 0],
   "origin": {"xyz": [0.4, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.01, "com": [0.005, 0, 0],
                 "inertia": {"ixx": 1e-8, "iyy": 1e-7, "izz": 1e-7}}]}]})";

nlohmann::json json_of(const std::string& out) {
  const auto open = out.find('{');
  REQUIRE(open != std::string::npos);
  return nlohmann::json::parse(out.substr(open, out.rfind('}') - open + 1));
}

}  // namespace

TEST_CASE("divergence: the issue's spring at dt = 1.5 s fails as diverging, with its limit",
          "[divergence]") {
  Scratch s("div_spring");
  std::ofstream(s / "spring10.json") << arm_json(100);
  const Run r = run("simulate " + (s / "spring10.json") +
                    " --t-end 20 --integrator rk4 --dt 1.5 --q0 0.1 --json");
  INFO(r.out);
  CHECK(r.code == 1);
  const nlohmann::json j = json_of(r.out);
  CHECK(j["ok"] == false);
  CHECK(j["diverged"] == true);
  const std::string why = j["failure"];
  CHECK_THAT(why, Catch::Contains("the solution diverges") &&
                      Catch::Contains("beyond the stability limit") &&
                      Catch::Contains("oscillatory at 10 rad/s") &&
                      Catch::Contains("limit ≈ 0.283 s"));
  // Found within a few steps of 1.5 s, not at the overflow dozens of steps later.
  CHECK(j["t_reached"].get<double>() <= 6.0);
  const std::string line = r.out.substr(r.out.find("femdyn simulate: "));
  CHECK(std::count(line.begin(), line.end(), '\n') == 1);  // one line
  CHECK(r.out.find("nan") == std::string::npos);
  // The balance's scale is fixed: the 0.5 J the spring started with (no work is done).
  CHECK(j["energy_scale"].get<double>() == Approx(0.5));
}

TEST_CASE("divergence: the arm on a rail at 1.2x its rk4 limit diverges, M^s is not blamed",
          "[divergence]") {
  Scratch s("div_rail");
  std::ofstream(s / "arm.json") << kRailArm;
  const Model m = load_text(kRailArm);
  // The limit `check` computes at the start state (here at rest, q = 0.3 on each link).
  const VecX q0 = (VecX(4) << 0, 0.3, 0.3, 0.3).finished(), qd0 = VecX::Zero(4);
  Workspace ws(m);
  const Linearization lin = linearize(m, ws, q0, qd0, VecX::Zero(4));
  REQUIRE(lin.status.ok);
  const double limit = *largest_stable_step(lin, IntegratorKind::Rk4);
  const double dt = 1.2 * limit;
  INFO("rk4 limit " << limit << " s");
  const Run r = run("simulate " + (s / "arm.json") + " --t-end 30 --integrator rk4 --dt " +
                    std::to_string(dt) + " --q0 0,0.3,0.3,0.3 --json");
  INFO(r.out);
  CHECK(r.code == 1);
  const nlohmann::json j = json_of(r.out);
  CHECK(j["diverged"] == true);
  const std::string why = j["failure"];
  CHECK_THAT(why, Catch::Contains("the solution diverges"));
  CHECK(why.find("singular") == std::string::npos);
  // At the step `femdyn check` recommends, the same run is followed, not called diverged.
  const Run check = run("check " + (s / "arm.json") + " --json");
  INFO(check.out);
  const double advised = json_of(check.out)["recommended"]["rk4_dt"].get<double>();
  REQUIRE(advised > 0);
  const Run ok = run("simulate " + (s / "arm.json") + " --t-end 30 --integrator rk4 --dt " +
                     std::to_string(advised) + " --q0 0,0.3,0.3,0.3 --json");
  INFO(ok.out);
  CHECK(ok.code == 0);
  CHECK(json_of(ok.out)["diverged"] == false);
}

TEST_CASE("divergence: falling, driven, damped and inaccurate runs are not called diverged",
          "[divergence]") {
  // A carriage falling freely from the world origin (E(0) = 0: only the fall's own energy).
  const Model fall = load_text(R"({"name": "fall", "gravity": [0, 0, -9.81], "bodies": [
    {"name": "cart", "parent": "world", "joint": {"name": "z", "type": "prismatic",
     "axis": [0, 0, 1]}, "elements": [{"type": "lumped_point", "node": [0, 0, 0],
     "mass": 1.0}]}]})");
  // A pendulum released horizontally about the origin (E(0) = 0 again), with coarse euler
  // steps: inaccurate (its energy drifts) but not diverging.
  const Model pendulum = load_text(arm_json(0, 0, 9.81));
  // A damped arm driven by a large constant torque (W grows, dampers take energy out).
  const Model driven = load_text(arm_json(100, 5));
  struct Case {
    const Model* m;
    IntegratorOptions o;
    double t_end;
    std::function<void(double, VecX&)> tau;
  } cases[] = {{&fall, {.kind = IntegratorKind::Rk4, .fixed = {.dt = 0.01}}, 100, {}},
               {&pendulum, {.kind = IntegratorKind::Euler, .fixed = {.dt = 0.02}}, 200, {}},
               {&pendulum, {.kind = IntegratorKind::Rk4, .fixed = {.dt = 0.2}}, 200, {}},
               {&driven,
                {.kind = IntegratorKind::Rk4, .fixed = {.dt = 0.01}},
                100,
                [](double t, VecX& u) { u.setConstant(1, 1e3 * std::sin(3 * t)); }},
               {&driven, {.kind = IntegratorKind::Dopri}, 100, [](double, VecX& u) {
                  u.setConstant(1, 1e4);
                }}};
  for (const Case& c : cases) {
    auto integ = make_integrator(*c.m, c.o, c.tau);
    integ->reset(0, VecX::Zero(1), VecX::Zero(1), c.t_end);
    const RecordedRun run = run_recorded(
        *integ, c.t_end, 1, nullptr, [](const Integrator&, const Energy&) {},
        [](double) { return false; });
    INFO(c.m->name << " " << integ->name() << ": " << run.status.message);
    CHECK(run.status.ok);
    CHECK(integ->t() == c.t_end);
  }
}

TEST_CASE("fixed steps lie on the grid t0 + k dt and the last row lands on t_end", "[divergence]") {
  const Model m = load_text(arm_json(100));
  for (IntegratorKind kind : {IntegratorKind::Rk4, IntegratorKind::Euler}) {
    auto integ = make_integrator(m, {.kind = kind, .fixed = {.dt = 1e-3}});
    integ->reset(0, VecX::Constant(1, 0.1), VecX::Zero(1), 2.0);
    std::vector<double> times;
    const RecordedRun run = run_recorded(
        *integ, 2.0, 1, nullptr,
        [&](const Integrator& i, const Energy&) { times.push_back(i.t()); },
        [](double) { return false; });
    REQUIRE(run.status.ok);
    CHECK(integ->stats().steps == 2000);  // not 2001 with a last step of 1e-13 s
    REQUIRE(times.size() == 2001);
    CHECK(times.back() == 2.0);
    for (std::size_t k = 0; k < times.size(); ++k) CHECK(times[k] == static_cast<double>(k) * 1e-3);
    // An output time off the grid is landed on, and the steps return to the grid after it.
    integ->reset(0, VecX::Constant(1, 0.1), VecX::Zero(1), 1.0);
    REQUIRE(integ->advance_to(0.0105).ok);
    CHECK(integ->t() == 0.0105);
    REQUIRE(integ->step().ok);
    CHECK(integ->t() == 11 * 1e-3);
  }
}

TEST_CASE("runs that cannot finish are refused before they start", "[divergence]") {
  const std::string pendulum = model_path("pendulum.json");
  // dt = 1e-300: t + dt == t; and 1e9 steps beyond the default limit of 1e7.
  Run r = run("simulate " + pendulum + " --t-end 1 --integrator rk4 --dt 1e-300");
  INFO(r.out);
  CHECK(r.code != 0);
  CHECK_THAT(r.out, Catch::Contains("below the resolution of the time"));
  r = run("simulate " + pendulum + " --t-end 1e6 --integrator euler");
  INFO(r.out);
  CHECK(r.code != 0);
  CHECK_THAT(r.out, Catch::Contains("1e+09 steps") && Catch::Contains("--max-steps") &&
                        Catch::Contains("evaluations of forward dynamics, about"));
  // Raising the limit lets a run through (a short one here).
  r = run("simulate " + pendulum + " --t-end 0.01 --integrator rk4 --dt 1e-6 --max-steps 20000");
  INFO(r.out);
  CHECK(r.code == 0);
  // An output far larger than the disk is refused up front, the file untouched.
  Scratch s("div_size");
  r = run("simulate " + pendulum + " --t-end 1e6 --dt 1e-3 --integrator rk4 --max-steps 1e15 " +
          "--out " + (s / "huge.csv"));
  INFO(r.out);
  CHECK(r.code != 0);
  CHECK_THAT(r.out, Catch::Contains("GB") && Catch::Contains("--every"));
  CHECK_FALSE(fs::exists(s / "huge.csv"));
}

TEST_CASE("simulate --sample-dt: rows at uniform times from dense output, the last at t_end",
          "[divergence]") {
  Scratch s("div_sample");
  std::ofstream(s / "spring.json") << arm_json(100);
  const Run r =
      run("simulate " + (s / "spring.json") +
          " --t-end 1 --sample-dt 0.3 --q0 0.1 --rtol 1e-10 --atol 1e-12 --out " + (s / "t.csv"));
  INFO(r.out);
  REQUIRE(r.code == 0);
  std::ifstream in(s / "t.csv");
  std::string line;
  std::getline(in, line);
  std::vector<double> t, q;
  while (std::getline(in, line)) {
    t.push_back(std::stod(line));
    q.push_back(std::stod(line.substr(line.find(',') + 1)));
  }
  REQUIRE(t.size() == 5);
  const double expect[] = {0, 0.3, 0.6, 0.9, 1.0};
  for (int k = 0; k < 5; ++k) {
    CHECK(t[k] == Approx(expect[k]).margin(1e-15));
    CHECK(q[k] == Approx(0.1 * std::cos(10 * expect[k])).margin(1e-8));
  }
}

TEST_CASE("joint limits left are reported once per joint with the time and the value",
          "[divergence]") {
  Scratch s("div_limits");
  nlohmann::json m = nlohmann::json::parse(arm_json(0, 0, 9.81));
  m["bodies"][0]["joint"]["limits"] = {-0.5, 0.5};
  std::ofstream(s / "limited.json") << m.dump();
  // Falling from horizontal (θ = 0) about y under gravity along −z: θ̈ = g cos θ > 0.
  const Run text = run("simulate " + (s / "limited.json") + " --t-end 2");
  INFO(text.out);
  REQUIRE(text.code == 0);
  CHECK_THAT(text.out, Catch::Contains("warning: joint 'theta' left its limits [-0.5, 0.5]"));
  CHECK(text.out.find("warning") == text.out.rfind("warning"));  // once
  const Run r = run("simulate " + (s / "limited.json") + " --t-end 2 --json");
  INFO(r.out);
  REQUIRE(r.code == 0);
  const nlohmann::json j = json_of(r.out);
  REQUIRE(j["limit_crossings"].size() == 1);
  const auto& c = j["limit_crossings"][0];
  CHECK(c["joint"] == "theta");
  CHECK(c["value"].get<double>() > 0.5);
  CHECK(c["value"].get<double>() < 0.7);  // found at the first step past the limit
  // θ(t) ≈ 0.5 near t = √(2 · 0.5 / g) for small angles (the exact fall is a little slower).
  CHECK(c["t"].get<double>() == Approx(0.33).margin(0.05));
}

TEST_CASE("track: gains beyond the step's stability are named, with the theory's limits",
          "[divergence][control]") {
  // Computed torque leaves the tracking error ë + kd ė + kp e = 0: at kp = 1e8, kd = 2e4 a double
  // root λ = −1e4 1/s. Inside f, rk4 is stable for |λ| dt ≤ 2.785: dt ≤ 2.785e-4 s. Held over
  // each step, e_{k+1} = Φ e_k with Φ = [[1 − kp dt²/2, dt − kd dt²/2], [−kp dt, 1 − kd dt]]
  // (the double integrator under a held input), stable while ρ(Φ) ≤ 1. The report's limits are
  // the controller diagnosis's (differences of the law, Van Loan), compared with these.
  const double kp = 1e8, kd = 2e4;
  double lo = 1e-9, hi = 1e-2;  // the held loop's largest stable period, by bisection
  for (int i = 0; i < 200; ++i) {
    const double dt = std::sqrt(lo * hi);
    Eigen::Matrix2d Phi;
    Phi << 1 - kp * dt * dt / 2, dt - kd * dt * dt / 2, -kp * dt, 1 - kd * dt;
    (Phi.eigenvalues().cwiseAbs().maxCoeff() <= 1 + 1e-12 ? lo : hi) = dt;
  }
  const std::string track = "track " + model_path("finger.json") +
                            " --to 0.5,0.5,0.5,0.5 --kp 1e8 --kd 2e4 --duration 0.1";
  // The number after `key`, looked for after `from`.
  const auto number_after = [](const std::string& text, const std::string& key,
                               const std::string& from = "") {
    const std::size_t at = text.find(key, text.find(from));
    REQUIRE(at != std::string::npos);
    return std::stod(text.substr(at + key.size()));
  };
  const Run in_f = run(track + " --steps 300 --control evaluation");  // dt = 3.33e-4 s
  INFO(in_f.out);
  CHECK(in_f.code == 1);
  CHECK_THAT(in_f.out, Catch::Contains("the controller is the likely cause") &&
                           Catch::Contains("(--kp 1e+08, --kd 20000)"));
  CHECK(number_after(in_f.out, " s (", "limit of the step ") == Approx(2.785e-4).epsilon(0.01));
  const Run held = run(track + " --steps 300");
  INFO(held.out);
  CHECK(held.code == 1);
  CHECK(number_after(held.out, "below a period of about ") == Approx(lo).epsilon(0.02));
  CHECK(held.out.find("nan") == std::string::npos);
  // Inside both limits the same gains track.
  CHECK(run(track + " --steps 1000 --control evaluation").code == 0);
  CHECK(run(track + " --steps " + std::to_string(static_cast<int>(0.1 / (0.7 * lo)))).code == 0);
}
