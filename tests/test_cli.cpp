// The femdyn command end to end: JSON output equals the library, bad input exits non-zero
// with one line naming file and path.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "core/derivatives/derivatives.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

VecX vec(const nlohmann::json& j) {
  VecX v(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) v[i] = j[i].get<double>();
  return v;
}

}  // namespace

TEST_CASE("femdyn equations --json equals the library on the spatial double pendulum", "[cli]") {
  const std::string path = model_path("spatial_double_pendulum.json");
  const Run r =
      run("equations " + path + " --q 0.4,-1.1 --qd 1.5,-0.7 --tau 0.2,0.1 --json --tensor");
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  const Model m = load_model(path);
  Workspace ws(m);
  VecX q(2), qd(2), tau(2);
  q << 0.4, -1.1;
  qd << 1.5, -0.7;
  tau << 0.2, 0.1;
  REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
  evaluate(m, ws, q, qd, tau);
  CHECK(j["coordinates"] == nlohmann::json({"hinge1", "hinge2"}));
  CHECK(rel_error(vec(j["h"]), ws.h) < 1e-15);
  CHECK(rel_error(vec(j["Q"]), ws.Q) < 1e-15);
  CHECK(rel_error(vec(j["qdd"]), ws.qdd) < 1e-15);
  for (int a = 0; a < 2; ++a) CHECK(rel_error(vec(j["M"][a]), ws.Ms.row(a).transpose()) < 1e-15);
  // M q̈ + h = Q holds in the printed numbers, and h = D[q̇,q̇].
  MatX M(2, 2);
  for (int a = 0; a < 2; ++a) M.row(a) = vec(j["M"][a]).transpose();
  CHECK(rel_error(M * vec(j["qdd"]) + vec(j["h"]), vec(j["Q"])) < 1e-13);
  for (int a = 0; a < 2; ++a) {
    MatX Da(2, 2);
    for (int b = 0; b < 2; ++b) Da.row(b) = vec(j["D"][a][b]).transpose();
    CHECK(std::abs(qd.dot(Da * qd) - ws.h[a]) < 1e-12 * ws.h.norm());
  }
}

TEST_CASE("the gravity option overrides the model's gravity", "[cli]") {
  const Run r =
      run("equations " + model_path("pendulum.json") + " --q 0.5 --gravity 0,0,-1 --json");
  REQUIRE(r.code == 0);
  CHECK(std::abs(nlohmann::json::parse(r.out)["Q"][0].get<double>() + std::sin(0.5)) < 1e-14);
}

TEST_CASE("bad command lines and bad models: one line, non-zero exit", "[cli]") {
  const std::string pend = model_path("pendulum.json");
  Run r = run("equations " + pend + " --q 1,2");
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn equations: --q has 2 values, expected 1 (theta)\n");
  r = run("equations " + pend + " --q nan");
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn equations: --q: 'nan' is NaN or Inf\n");
  r = run("equations " + pend + " --bogus");
  CHECK(r.code == 2);
  r = run("equations /nonexistent.json");
  CHECK(r.code == 1);
  CHECK(r.out ==
        "femdyn equations: /nonexistent.json: cannot open file: No such file or directory\n");
  const std::string bad = "femdyn_test_bad.json";
  std::ofstream(bad)
      << R"({"bodies": [{"name": "a", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]}, "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": NaN}}]}]})";
  r = run("info " + bad);
  CHECK(r.code == 1);
  CHECK_THAT(r.out,
             Catch::StartsWith("femdyn info: femdyn_test_bad.json: malformed JSON at line 1"));
  CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  std::remove(bad.c_str());
}

TEST_CASE("every command has --help, info lists the correlation table", "[cli]") {
  for (const char* cmd : {"info", "equations", "compare", "track", "validate", "import", "simulate",
                          "check", "study", "stress", "bench", "linearize"}) {
    const Run r = run(std::string(cmd) + " --help");
    CHECK(r.code == 0);
    CHECK_THAT(r.out, Catch::StartsWith("usage: femdyn " + std::string(cmd)));
  }
  const Run r = run("info " + model_path("double_pendulum_planar.json"));
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("1 space_bar     [0, 0, 0, 0, 0, 1 | 2, 3, 0, 0, 0, 1]"));
  CHECK_THAT(r.out, Catch::Contains("2 space_bar     [2, 3, 0, 0, 0, 4 | 5, 6, 0, 0, 0, 4]"));
}

TEST_CASE("every bundled model loads and has a positive definite M^s", "[cli]") {
  for (const std::string& name : bundled_models()) {
    INFO(name);
    const Run r = run("equations " + model_path(name) + " --json");
    CHECK(r.code == 0);
  }
}

TEST_CASE("track on a floating base: the feed-forward along the geodesic is exact",
          "[cli][joints]") {
  // HyQ floating under gravity, from the neutral pose to a turned, lifted base and bent legs:
  // open-loop RK4 under τ(t) = ID(q_ref, v_ref, v̇_ref) follows q_ref to RK4's error, which
  // falls 16x per halving of the step only if v_ref and v̇_ref are q_ref's exact derivatives.
  const std::string hyq = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/hyq.urdf";
  const Eigen::Vector4d quat = Eigen::Vector4d(0.9, 0.2, -0.3, 0.25).normalized();
  std::ostringstream to;
  to.precision(17);
  to << "0.1,-0.05,0.2," << quat[0] << "," << quat[1] << "," << quat[2] << "," << quat[3];
  for (int k = 0; k < 12; ++k) to << "," << 0.2 + 0.03 * k;
  double previous = 0;
  for (const int steps : {100, 200, 400}) {
    const Run r = run("track " + hyq + " --floating-base --actuated-base --to " + to.str() +
                      " --duration 0.5 --json --steps " + std::to_string(steps));
    INFO(r.out);
    REQUIRE(r.code == 0);
    const double e = nlohmann::json::parse(r.out)["max_tracking_error"];
    if (previous > 0) CHECK(previous / e > 12);
    previous = e;
  }
  CHECK(previous < 1e-6);
}

TEST_CASE("track --kp --kd closes the loop: the error from an offset start decays",
          "[cli][control]") {
  // Computed torque with PD (ω = 20 rad/s, critically damped) from a start 0.1 rad off every
  // joint: per evaluation the error obeys ë + 2ω ė + ω² e = 0 exactly, e(t) = e0 (1 + ω t)
  // exp(−ω t), 4.3e-9 rad at t = 1 s. Held at 1/dt the sampled τ lags by O(dt): the error at
  // 1 s is that lag's, and halves when dt halves.
  const std::string finger = model_path("finger.json");
  const std::string motion = " --to 0.3,0.5,0.4,0.2 --duration 1 --json";
  const std::string start = " --start 0.1,0.1,0.1,0.1 --kp 400 --kd 40";
  const double e0 = 0.1, omega = 20, decayed = e0 * (1 + omega) * std::exp(-omega);
  const auto final_error = [&](const std::string& control, int steps) {
    const Run r = run("track " + finger + motion + start + " --control " + control + " --steps " +
                      std::to_string(steps));
    INFO(r.out);
    REQUIRE(r.code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["max_tracking_error"].get<double>() == Approx(e0).epsilon(1e-12));  // at t = 0
    CHECK(j["feedback"]["control"] == control);
    return j["final_tracking_error"].get<double>();
  };
  CHECK(final_error("evaluation", 1000) == Approx(decayed).epsilon(1e-3));
  const double held = final_error("hold", 1000), finer = final_error("hold", 2000);
  CHECK(held < 1e-4);
  CHECK(held / finer == Approx(2).epsilon(0.1));
  const Run gains_alone = run("track " + finger + motion + " --kp 400");
  CHECK(gains_alone.code == 2);
  CHECK_THAT(gains_alone.out, Catch::Contains("--kp and --kd go together"));
  const Run open = run("track " + finger + motion + " --start 0.1,0.1,0.1,0.1");
  CHECK(open.code == 2);
  CHECK_THAT(open.out, Catch::Contains("--start needs --kp and --kd"));
}

TEST_CASE("track: feed-forward torques from inverse dynamics reproduce the motion", "[cli]") {
  for (const char* name : {"finger_coupled.json", "branched_tree.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    std::string to;
    for (int a = 0; a < m.n(); ++a) to += (a ? "," : "") + std::to_string(0.1 + 0.05 * a);
    const std::string csv = "femdyn_test_track.csv";
    const Run r = run("track " + model_path(name) + " --to " + to +
                      " --duration 0.4 --steps 400 --json --csv " + csv);
    REQUIRE(r.code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["max_abs_tau"].get<double>() > 1e-4);         // it needed torque
    CHECK(j["max_tracking_error"].get<double>() < 1e-8);  // RK4 error only
    std::ifstream f(csv);
    std::string header;
    std::getline(f, header);
    CHECK(std::count(header.begin(), header.end(), ',') == 3 * m.n());
    int lines = 0;
    for (std::string line; std::getline(f, line);) ++lines;
    CHECK(lines == 401);
    std::remove(csv.c_str());
  }
}

TEST_CASE("compare: a model against itself is exact, the paper's finger is not", "[cli]") {
  Run r = run("compare " + model_path("finger.json") + " " + model_path("finger.json") +
              " --states 5 --json");
  REQUIRE(r.code == 0);
  auto j = nlohmann::json::parse(r.out);
  CHECK(j["max_rel_error"]["M"].get<double>() == 0.0);
  r = run("compare " + model_path("finger_paper.json") + " " + model_path("finger.json") +
          " --states 20 --json");
  REQUIRE(r.code == 0);
  j = nlohmann::json::parse(r.out);
  CHECK(j["max_rel_error"]["M"].get<double>() > 0.01);
  r = run("compare " + model_path("finger.json") + " " + model_path("finger_coupled.json"));
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn compare: the models have 4 and 3 coordinates; compare needs the same\n");
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("validate: table and exit 0 on a good model, JSON, exit 1 when it cannot match",
          "[cli][validation]") {
  const Run text = run("validate " + model_path("finger.json") + " --states 5 --t-end 0.1");
  CHECK(text.code == 0);
  for (const char* row : {"M^s", "h ", "Q ", "qdd", "tau", "trajectory"})
    CHECK_THAT(text.out, Catch::Contains(row));
  CHECK_THAT(text.out, Catch::EndsWith("PASS\n"));

  const Run js = run("validate " + model_path("finger_coupled.json") +
                     " --states 4 --seed 3 --t-end 0.05 --json");
  REQUIRE(js.code == 0);
  const auto j = nlohmann::json::parse(js.out);
  CHECK(j.at("states") == 4);
  CHECK(j.at("pass") == true);
  for (const char* q : {"M", "h", "Q", "qdd", "tau"})
    CHECK(j.at("max_rel_error").at(q).get<double>() < 1e-10);
  CHECK(j.at("trajectory").at("t_end") == 0.05);
  CHECK(j.at("trajectory").at("max_state_error").get<double>() < 1e-6);
  const auto& traj = j.at("trajectory");
  REQUIRE(traj.at("t").size() == traj.at("state_error").size());
  REQUIRE(traj.at("energy").at("femdyn").size() == traj.at("t").size());
  for (std::size_t i = 0; i < traj.at("t").size(); ++i)  // the same energy in both engines
    CHECK(traj.at("energy").at("femdyn")[i].get<double>() ==
          Approx(traj.at("energy").at("simbody")[i].get<double>()).margin(1e-12));

  const Run urdf = run("validate " + model_path("urdf/arm7.urdf") + " --states 3 --t-end 0.05");
  CHECK(urdf.code == 0);
  CHECK_THAT(urdf.out, Catch::Contains("import "));  // the import against the XML twin
  CHECK(
      run("validate " + model_path("urdf/arm7.urdf") + " --states 2 --t-end 0 --gravity 0,-9.81,0")
          .code == 0);

  // track takes n_q values: a wrong count is named in one line with the configuration's names.
  const Run track = run("track " + std::string(FEMDYN_SOURCE_DIR) +
                        "/tests/robots/hyq.urdf --floating-base --actuated-base --to 0");
  CHECK(track.code != 0);
  CHECK_THAT(track.out,
             Catch::Contains("--to has 1 values, expected 19 (base_link_0.x, base_link_0.y"));
  // A floating base: the import check floats the XML's root link too.
  const Run hyq = run("validate " + std::string(FEMDYN_SOURCE_DIR) +
                      "/tests/robots/hyq.urdf --floating-base --states 2 --t-end 0.02");
  CHECK(hyq.code == 0);
  CHECK_THAT(hyq.out, Catch::Contains("import ") && Catch::EndsWith("PASS\n"));
  // Floating, with <mimic> couplings after the quaternion (θ = C_q q + θ0_q).
  const Run hand = run("validate " + model_path("urdf/hand16.urdf") +
                       " --floating-base --states 2 --t-end 0.02");
  CHECK(hand.code == 0);
  CHECK_THAT(hand.out, Catch::Contains("import ") && Catch::EndsWith("PASS\n"));

  const Run paper = run("validate " + model_path("finger_paper.json") + " --states 2");
  CHECK(paper.code == 1);
  CHECK_THAT(paper.out, Catch::Contains("its elements sum to no rigid body"));

  const Run wrong_tol = run("validate " + model_path("pendulum.json") + " --states 0");
  CHECK(wrong_tol.code == 2);
  CHECK_THAT(wrong_tol.out, Catch::Contains("--states expects one integer >= 1"));
}

TEST_CASE("validate: a 10000-body chain is refused up front in seconds, with the way on",
          "[cli][validation]") {
  // The issue's case: the random_tree plugin, 10,000 bodies in one chain. Its 20 states take
  // about 13 s here and its trajectory many minutes: beyond --budget 30 on any machine up to
  // several times faster. The time is a generous guard, not a speed claim (about 3 s measured).
  const std::string path =
      (std::filesystem::temp_directory_path() / "femdyn_cli_chain10000.json").string();
  std::ofstream(path) << R"({"model": "random_tree", "params": {"seed": 3, "bodies": 10000, )"
                      << R"("branching": 0}})";
  const auto t0 = std::chrono::steady_clock::now();
  const Run r = run("validate " + path + " --budget 30");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  INFO(r.out << "(" << seconds << " s)");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::StartsWith("femdyn validate: " + path +
                                      ": validating n = 10000 coordinates would take "));
  CHECK_THAT(r.out, Catch::Contains(" of memory, beyond the budget of 30 s: use --t-end 0 "));
  CHECK_THAT(r.out, Catch::Contains("--budget "));
  CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // one line, nothing else
  CHECK(seconds < 60);
  // The memory limit, and the options' own checks.
  const Run memory = run("validate " + model_path("finger.json") + " --max-memory 1e-6");
  CHECK(memory.code == 1);
  CHECK_THAT(memory.out, Catch::Contains("beyond the memory limit of 1 kB: use --max-memory "));
  CHECK(run("validate " + model_path("finger.json") + " --budget 0").code == 2);
  CHECK(run("validate " + model_path("finger.json") + " --max-memory -1").code == 2);
  std::filesystem::remove(path);
}

namespace {

// The engine and quantity of each row of `femdyn bench --json`, each row checked to be a finite,
// positive, ordered min ≤ median ≤ max and to appear once.
std::set<std::string> bench_rows(const nlohmann::json& j) {
  std::set<std::string> timed;
  for (const auto& r : j.at("results")) {
    const std::string what =
        r.at("engine").get<std::string>() + " " + r.at("quantity").get<std::string>();
    INFO(what);
    const double median = r.at("median_ns"), lo = r.at("min_ns"), hi = r.at("max_ns");
    CHECK(std::isfinite(lo));
    CHECK(std::isfinite(hi));
    CHECK(0 < lo);
    CHECK(lo <= median);
    CHECK(median <= hi);
    CHECK(timed.insert(what).second);  // once each
  }
  return timed;
}

}  // namespace

TEST_CASE(
    "bench: every quantity timed on both engines, the derivatives on femdyn, D skipped as "
    "documented, bad input",
    "[cli][bench]") {
#ifndef NDEBUG  // a Debug build (as this test's): bench refuses to time it
  const Run refused = run("bench " + model_path("finger.json") + " --quick");
  CHECK(refused.code == 2);
  CHECK_THAT(refused.out, Catch::StartsWith("femdyn bench: refusing to time a Debug build ("));
  return;
#endif
  // --quick --json on the finger: stdout is the JSON, stderr says D was not timed.
  const auto tmp = std::filesystem::temp_directory_path();
  const std::string err = (tmp / "femdyn_cli_bench.err").string();
  const Run js = run_shell("{ " + std::string(FEMDYN_BINARY) + " bench " +
                           model_path("finger.json") + " --quick --json 2>" + err + "; }");
  REQUIRE(js.code == 0);
  const auto j = nlohmann::json::parse(js.out);
  CHECK(j.at("model") == model_path("finger.json"));
  CHECK(j.at("n") == 4);
  CHECK(j.at("build") != "Debug");
  const std::set<std::string> timed = bench_rows(j);
  for (const char* engine : {"femdyn", "simbody"})
    for (const char* quantity : {"M", "h", "g", "Q", "qdd", "tau"})
      CHECK(timed.count(std::string(engine) + " " + quantity) == 1);
  for (const char* quantity : {"dtau", "dqdd"})  // femdyn alone
    CHECK(timed.count(std::string("femdyn ") + quantity) == 1);
  CHECK(timed.size() == 14);  // and no D: --quick skips it
  std::ifstream note(err);
  const std::string stderr_text((std::istreambuf_iterator<char>(note)), {});
  CHECK(stderr_text == "femdyn bench: D not timed (--quick)\n");
  std::remove(err.c_str());

  // Above 40 coordinates D is skipped too; the table says why.
  const std::string big = (tmp / "femdyn_cli_bench41.json").string();
  std::ofstream(big) << R"({"model": "random_tree", "params": {"seed": 3, "bodies": 41}})";
  const Run table = run("bench " + big + " --quick --states 2");
  CHECK(table.code == 0);
  CHECK_THAT(table.out, Catch::Contains("(41 coordinates)"));
  CHECK_THAT(table.out, Catch::Contains("\nqdd "));
  CHECK_THAT(table.out,
             Catch::Contains("\nquantity     femdyn      femdyn/qdd   femdyn min-max\n"));
  CHECK_THAT(table.out, Catch::Contains("\ndqdd "));
  CHECK_THAT(table.out, Catch::EndsWith("\nD        skipped (n = 41 > 40 and --quick)\n"));
  std::remove(big.c_str());

  // Bad command lines and models: one line, non-zero exit.
  Run bad = run("bench " + model_path("finger.json") + " --bogus");
  CHECK(bad.code == 2);
  CHECK(bad.out == "femdyn bench: unknown option --bogus (try --help)\n");
  bad = run("bench " + model_path("finger.json") + " --states 0");
  CHECK(bad.code == 2);
  CHECK(bad.out == "femdyn bench: --states expects one integer >= 1\n");
  bad = run("bench /nonexistent.json --quick");
  CHECK(bad.code == 1);
  CHECK(bad.out ==
        "femdyn bench: /nonexistent.json: cannot open file: No such file or directory\n");
}

#ifdef NDEBUG  // (bench refuses to time a build with asserts)
TEST_CASE("bench: a model with loop constraints gains the constrained q̈ (qdd_c) on both engines",
          "[cli][bench][loops]") {
  const std::string delta = model_path("delta.json");
  const Run js = run_shell("{ " + std::string(FEMDYN_BINARY) + " bench " + delta +
                           " --quick --states 2 --json 2>/dev/null; }");
  REQUIRE(js.code == 0);
  const auto j = nlohmann::json::parse(js.out);
  CHECK(j.at("n") == 9);
  const std::set<std::string> timed = bench_rows(j);
  for (const char* engine : {"femdyn", "simbody"})
    for (const char* quantity : {"M", "h", "g", "Q", "qdd", "qdd_c", "tau"})
      CHECK(timed.count(std::string(engine) + " " + quantity) == 1);
  // and femdyn's derivatives (dqdd: of the constrained equations, ω = 0)
  for (const char* quantity : {"dtau", "dqdd"})
    CHECK(timed.count(std::string("femdyn ") + quantity) == 1);
  CHECK(timed.size() == 16);
  // The table has the row, and no warning: the engines agree on the constrained q̈.
  const Run table = run("bench " + delta + " --quick --states 2");
  CHECK(table.code == 0);
  CHECK_THAT(table.out, Catch::StartsWith(delta + " (9 coordinates) against Simbody"));
  CHECK_THAT(table.out, Catch::Contains("\nqdd_c "));
}
#endif

#if defined(FEMDYN_WITH_MUJOCO) && defined(NDEBUG)
TEST_CASE("bench: a URDF robot is timed on MuJoCo too (M, qdd, tau), a mimic joint is left out",
          "[cli][bench][mujoco]") {
  const std::string hyq = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/hyq.urdf";
  const Run js = run_shell("{ " + std::string(FEMDYN_BINARY) + " bench " + hyq +
                           " --floating-base --quick --states 2 --json 2>/dev/null; }");
  REQUIRE(js.code == 0);
  const auto j = nlohmann::json::parse(js.out);
  std::set<std::string> mujoco;
  for (const auto& r : j.at("results"))
    if (r.at("engine") == "mujoco") {
      CHECK(r.at("median_ns").get<double>() > 0);
      mujoco.insert(r.at("quantity").get<std::string>());
    }
  CHECK(mujoco == std::set<std::string>{"M", "qdd", "tau"});
  const Run hand = run("bench " + model_path("urdf/hand16.urdf") + " --quick --states 2");
  CHECK(hand.code == 0);
  CHECK_THAT(hand.out, Catch::StartsWith("femdyn bench: warning: MuJoCo not timed: "));
  CHECK_THAT(hand.out, Catch::Contains("(a <mimic> joint?)\n"));
  CHECK_THAT(hand.out, Catch::Contains("against Simbody: median"));
}
#endif
#endif

TEST_CASE("import writes JSON that loads back, atomically, or nothing at all", "[cli][urdf]") {
  const std::string out =
      (std::filesystem::temp_directory_path() / "femdyn_cli_arm7.json").string();
  std::filesystem::remove(out);
  const Run ok = run("import " + model_path("urdf/arm7.urdf") + " -o " + out);
  REQUIRE(ok.code == 0);
  const Run a =
      run("equations " + model_path("urdf/arm7.urdf") + " --q 0.1,0.2,0.3,0.4,0.5,0.6,0.7 --json");
  const Run b = run("equations " + out + " --q 0.1,0.2,0.3,0.4,0.5,0.6,0.7 --json");
  REQUIRE(a.code == 0);
  CHECK(a.out == b.out);  // the same equations, digit for digit
  CHECK(nlohmann::json::parse(b.out).at("coordinates").at(0) == "joint1");
  // A URDF that does not load writes nothing.
  const std::string bad = (std::filesystem::temp_directory_path() / "femdyn_cli_bad.urdf").string();
  std::ofstream(bad) << "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/></robot>";
  const std::string bad_out = out + ".bad.json";
  std::filesystem::remove(bad_out);
  const Run no = run("import " + bad + " -o " + bad_out);
  CHECK(no.code == 1);
  CHECK_THAT(no.out, Catch::Contains("more than one root link"));
  CHECK_FALSE(std::filesystem::exists(bad_out));
  CHECK(run("import " + model_path("urdf/arm7.urdf")).code == 2);  // no -o
}

TEST_CASE("linearize --json equals the library on the space robot, bad input in one line",
          "[cli][derivatives]") {
  // A free-floating base: A's chart block, the forward derivatives and M⁻¹, as the library
  // computes them; the text form names its sizes.
  const std::string path = model_path("space_robot.json");
  const Model m = load_model(path);
  const int n = m.n();
  std::mt19937 rng(3);
  VecX q = random_posture(m, rng);
  const VecX qd = random_uniform(n, 0.5, rng), tau = random_uniform(n, 1, rng);
  const auto list = [](const VecX& v) {
    std::string s;
    char buf[32];
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      std::snprintf(buf, sizeof buf, "%s%.17g", i ? "," : "", v[i]);
      s += buf;
    }
    return s;
  };
  const Run r = run("linearize " + path + " --q " + list(q) + " --qd " + list(qd) + " --tau " +
                    list(tau) + " --json");
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  Workspace ws(m);
  DerivativeWorkspace d(m);
  normalize_quaternions(m, q);  // as the command does with what it reads
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok);
  MatX A, B;
  linearization(m, d, qd, A, B);
  CHECK(j["n"] == n);
  REQUIRE(j["A"].size() == static_cast<std::size_t>(2 * n));
  REQUIRE(j["B"].size() == static_cast<std::size_t>(2 * n));
  for (int a = 0; a < 2 * n; ++a) {
    CHECK(rel_error(vec(j["A"][a]), A.row(a).transpose(), 1e-300) == 0.0);
    CHECK(rel_error(vec(j["B"][a]), B.row(a).transpose(), 1e-300) == 0.0);
  }
  const Run text = run("linearize " + model_path("finger.json"));
  CHECK(text.code == 0);
  CHECK_THAT(text.out, Catch::Contains("A = d(xi', v')/d(xi, v) (8 x 8)"));
  // Coupling laws (with the four-bar's spanning coupler rod) and two-point springs are covered.
  for (const char* covered : {"finger_fourbar.json", "iftomm_a05_flyball.json"})
    CHECK(run("linearize " + model_path(covered)).code == 0);
  // Closed loops: at the state assembled onto them, at Baumgarte's rate (default or given).
  CHECK(run("linearize " + model_path("five_bar.json")).code == 0);
  CHECK(run("linearize " + model_path("five_bar.json") + " --baumgarte 0").code == 0);
  CHECK(run("linearize " + model_path("five_bar.json") + " --baumgarte -1").code == 2);
  CHECK(run("linearize " + model_path("finger.json") + " --baumgarte 5").code == 2);
  Run bad = run("linearize " + model_path("finger_paper.json"));
  CHECK(bad.code == 1);
  CHECK(std::count(bad.out.begin(), bad.out.end(), '\n') == 1);
  CHECK_THAT(bad.out, Catch::Contains("body-level form"));
  bad = run("linearize " + model_path("finger.json") + " --qd 1,2");
  CHECK(bad.code == 2);
  CHECK_THAT(bad.out, Catch::StartsWith("femdyn linearize: --qd has 2 values, expected 4"));
}

TEST_CASE("femdyn --version prints the version of CMakeLists.txt's project()", "[cli]") {
  std::ifstream f(std::string(FEMDYN_SOURCE_DIR) + "/CMakeLists.txt");
  const std::string cmake((std::istreambuf_iterator<char>(f)), {});
  std::smatch version;
  REQUIRE(std::regex_search(cmake, version, std::regex(R"(project\(femdyn VERSION ([0-9.]+))")));
  const Run r = run("--version");
  CHECK(r.code == 0);
  CHECK(r.out == "femdyn " + version[1].str() + "\n");
  const Run extra = run("--version now");
  CHECK(extra.code == 2);
  CHECK(extra.out == "femdyn --version: takes no arguments\n");
  CHECK_THAT(run("--help").out, Catch::Contains("femdyn --version"));
}

TEST_CASE("compare --rtol: exit 1 above the tolerance, 0 within it, 2 for a bad tolerance",
          "[cli]") {
  const std::string pair = " compare " + model_path("finger_paper.json") + " " +
                           model_path("finger.json") + " --states 5";
  const Run report = run(pair + " --json");
  REQUIRE(report.code == 0);  // without --rtol only a report
  const auto errors = nlohmann::json::parse(report.out).at("max_rel_error");
  double worst = 0;
  std::string worst_name;
  for (const auto& [key, shown] : {std::pair{"M", "M^s"}, {"h", "h"}, {"qdd", "qdd"}})
    if (errors.at(key).get<double>() > worst) worst = errors.at(key), worst_name = shown;
  REQUIRE(worst > 0.01);  // the paper's discretisation is not the exact finger
  char within[32], above[32];
  std::snprintf(within, sizeof within, "%.17g", worst * 1.01);
  std::snprintf(above, sizeof above, "%.17g", worst * 0.99);
  // Just above the largest error: exit 0. Just below it: exit 1, the quantity named on stderr
  // (one line) and "pass": false in the JSON on stdout.
  const Run pass = run(pair + " --rtol " + within);
  CHECK(pass.code == 0);
  CHECK_THAT(pass.out, Catch::EndsWith("PASS (--rtol " + format_number(worst * 1.01) + ")\n"));
  const std::string err =
      (std::filesystem::temp_directory_path() / "femdyn_cli_compare_rtol.err").string();
  const Run fail = run_shell("{ " + std::string(FEMDYN_BINARY) + pair + " --rtol " + above +
                             " --json 2>" + err + "; }");
  CHECK(fail.code == 1);
  const auto j = nlohmann::json::parse(fail.out);
  CHECK(j.at("pass") == false);
  CHECK(j.at("rtol").get<double>() == std::strtod(above, nullptr));
  std::ifstream e(err);
  const std::string stderr_text((std::istreambuf_iterator<char>(e)), {});
  CHECK_THAT(stderr_text, Catch::StartsWith("femdyn compare: max relative error above --rtol ") &&
                              Catch::Contains(": " + worst_name + " "));
  CHECK(std::count(stderr_text.begin(), stderr_text.end(), '\n') == 1);
  std::remove(err.c_str());
  // A model against itself is exact: it passes any tolerance.
  const std::string finger = model_path("finger.json");
  CHECK(run("compare " + finger + " " + finger + " --states 3 --rtol 1e-300").code == 0);
  // A tolerance must be a number > 0: one line, exit 2.
  for (const char* bad : {"0", "-1", "nan", "inf", "1e200", "abc", "1,2", "''"}) {
    INFO(bad);
    const Run r = run("compare " + finger + " " + finger + " --states 1 --rtol " + bad);
    CHECK(r.code == 2);
    CHECK_THAT(r.out, Catch::StartsWith("femdyn compare: --rtol"));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  CHECK(run("compare " + finger + " " + finger + " --rtol 0").out ==
        "femdyn compare: --rtol: 0 is not a tolerance (expected a number > 0)\n");
  CHECK_THAT(run("compare --help").out, Catch::Contains("--rtol R"));
}

TEST_CASE("every --json output: \"coordinates\" the names, \"n\" how many", "[cli]") {
  const std::string finger = model_path("finger.json");
  const Model m = load_model(finger);  // the names from the library, not from the CLI
  std::vector<std::string> commands = {
      "equations " + finger,
      "info " + finger,
      "simulate " + finger + " --t-end 0.01",
      "check " + finger + " --states 2",
      "compare " + finger + " " + finger + " --states 2",
      "track " + finger + " --to 0.1,0.2,0.3,0.4 --duration 0.1 --steps 10",
      "linearize " + finger};
#ifdef FEMDYN_WITH_SIMBODY
  commands.push_back("validate " + finger + " --states 2 --t-end 0");
#ifdef NDEBUG  // (bench refuses to time a build with asserts)
  commands.push_back("bench " + finger + " --quick --states 2");
#endif
#endif
  for (const std::string& command : commands) {
    INFO(command);
    const Run r =
        run_shell("{ " + std::string(FEMDYN_BINARY) + " " + command + " --json 2>/dev/null; }");
    CHECK(r.code == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j.at("coordinates") == nlohmann::json(m.coordinate_names));
    CHECK(j.at("n") == m.n());
  }
}
