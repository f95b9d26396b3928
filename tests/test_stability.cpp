// The stability diagnosis (sim/stability.hpp) against closed forms, the backward error of q̈ on
// an ill-conditioned M^s, femdyn check on a model with a culprit body, and every class of
// femdyn stress with its verdicts (docs/stability.md).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "core/derivatives/derivatives.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "sim/stability.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

}  // namespace

TEST_CASE("linearisation and stable steps match the closed forms of an oscillator", "[stability]") {
  const double w = 1e3;
  const Model m = load_text(arm_json(w * w, 0, 0));
  Workspace ws(m);
  const Linearization lin = linearize(m, ws, VecX::Constant(1, 0.1), VecX::Zero(1), VecX::Zero(1));
  REQUIRE(lin.status.ok);
  CHECK(lin.A(1, 0) == Approx(-w * w).epsilon(1e-6));  // θ̈ = −ω² θ
  CHECK(std::abs(lin.A(1, 1)) < 1e-6);
  CHECK(std::abs(lin.stiffest) == Approx(w).epsilon(1e-6));
  // RK4 on the imaginary axis: |R(iy)| ≤ 1 up to y = 2√2; symplectic Euler: ω h < 2.
  CHECK(*largest_stable_step(lin, IntegratorKind::Rk4) * w ==
        Approx(2 * std::sqrt(2.0)).epsilon(1e-4));
  CHECK(*largest_stable_step(lin, IntegratorKind::Euler) * w == Approx(2).epsilon(1e-4));
  CHECK(std::isinf(*largest_stable_step(lin, IntegratorKind::Bdf)));
  // Overdamped (ζ = 100): the fast real mode λ ≈ −2ζω limits RK4 to h |λ| ≤ 2.785.
  const Model damped = load_text(arm_json(w * w, 2 * 100 * w, 0));
  Workspace wd(damped);
  const Linearization fast =
      linearize(damped, wd, VecX::Constant(1, 0.1), VecX::Zero(1), VecX::Zero(1));
  CHECK(*largest_stable_step(fast, IntegratorKind::Rk4) * std::abs(fast.stiffest) ==
        Approx(2.785).epsilon(1e-3));
  // The arm under gravity, horizontal at θ = 0 (θ̈ = g cos θ): A = [[0, 1], [−g sin θ, 0]].
  const Model pendulum = load_text(arm_json(0, 0, 9.81));
  Workspace wp(pendulum);
  const Linearization p =
      linearize(pendulum, wp, VecX::Constant(1, 0.4), VecX::Zero(1), VecX::Zero(1));
  CHECK(p.A(1, 0) == Approx(-9.81 * std::sin(0.4)).epsilon(1e-6));
}

TEST_CASE("a Baumgarte rate's stable step is each method's real-axis bound over ω",
          "[stability][loops]") {
  // The residual's mode ë + 2ωė + ω²e = 0, a double eigenvalue −ω: RK4's boundary on the negative
  // real axis is the root of |1 + z + z²/2 + z³/6 + z⁴/24| = 1, z = −2.7852935; symplectic
  // Euler's on this damped pair 2√2 − 2 (det = 1 − 2x, tr² conditions: x² + 4x − 4 ≤ 0);
  // Dormand–Prince 5(4)'s about −3.3066; BDF none. The same at any scale of ω.
  for (const double w : {20.0, 1e4, 1e10}) {
    INFO("ω = " << w);
    CHECK(*baumgarte_stable_step(w, IntegratorKind::Rk4) * w == Approx(2.7852935).epsilon(1e-5));
    CHECK(*baumgarte_stable_step(w, IntegratorKind::Euler) * w ==
          Approx(2 * std::sqrt(2.0) - 2).epsilon(1e-5));
    CHECK(*baumgarte_stable_step(w, IntegratorKind::Dopri) * w == Approx(3.3066).epsilon(1e-3));
    CHECK(std::isinf(*baumgarte_stable_step(w, IntegratorKind::Bdf)));
  }
  // simulate refuses a rate its method cannot follow, in one line, before any work (it ran for
  // minutes); just inside the bound the run is made.
  const std::string five_bar = model_path("five_bar.json");
  for (const char* integrator : {"rk4", "euler", "dopri", "bdf"}) {
    const Run r = run("simulate " + five_bar + " --t-end 1 --integrator " +
                      std::string(integrator) + " --baumgarte 1e10");
    INFO(integrator << ": " << r.out);
    CHECK(r.code == 2);
    CHECK_THAT(r.out, Catch::StartsWith("femdyn simulate: --baumgarte 1e+10: "));
    const bool adaptive = std::string(integrator) == "dopri" || std::string(integrator) == "bdf";
    CHECK((r.out.find("--max-steps (1e+07)") != std::string::npos) == adaptive);
  }
  CHECK(run("simulate " + five_bar + " --t-end 0.2 --integrator rk4 --dt 0.001 --baumgarte 2700")
            .code == 0);
  CHECK(run("simulate " + five_bar + " --t-end 0.2 --integrator rk4 --dt 0.001 --baumgarte 2900")
            .code == 2);
}

TEST_CASE("at cond(M^s) = 1e10 the backward error of q̈ is below 1e-14", "[stability]") {
  // Two links whose masses differ by the ratio that makes cond(M^s) ≈ 1e10.
  for (double ratio : {1e9, 1e10}) {
    const Model m = load_text(R"({"name": "ratio", "gravity": [0, 0, -9.81], "bodies": [
      {"name": "heavy", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 1, 0]},
       "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1.0}]},
      {"name": "light", "parent": "heavy", "joint": {"name": "j2", "type": "revolute", "axis": [0, 0, 1],
       "origin": {"xyz": [0.5, 0, 0]}}, "elements": [{"type": "lumped_point", "node": [0.3, 0, 0],
       "mass": )" + number(1.0 / ratio) +
                              R"(}]}]})");
    Workspace ws(m);
    const VecX q = Eigen::Vector2d(0.3, 0.7), qd = Eigen::Vector2d(1.0, -2.0),
               tau = Eigen::Vector2d(0.1, 1e-9);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    evaluate(m, ws, q, qd, tau);
    const MassMatrixHealth h = mass_matrix_health(ws.Ms);
    INFO("cond " << h.condition);
    CHECK(h.condition > 1e9);
    CHECK(h.condition < 1e12);
    // ‖M q̈ − (Q − h)‖∞ / (‖M‖∞ ‖q̈‖∞ + ‖Q − h‖∞): Cholesky is backward stable.
    const VecX r = ws.Ms * ws.qdd - (ws.Q - ws.h);
    const double scale =
        ws.Ms.cwiseAbs().rowwise().sum().maxCoeff() * ws.qdd.cwiseAbs().maxCoeff() +
        (ws.Q - ws.h).cwiseAbs().maxCoeff();
    INFO("backward error " << r.cwiseAbs().maxCoeff() / scale);
    CHECK(r.cwiseAbs().maxCoeff() / scale <= 1e-14);
  }
}

TEST_CASE("femdyn check names the culprit body of a model with a 1e-9 kg link",
          "[stability][cli]") {
  const std::string path =
      (std::filesystem::temp_directory_path() / "femdyn_check_culprit.json").string();
  std::ofstream(path) << R"({"name": "culprit", "gravity": [0, 0, -9.81], "bodies": [
    {"name": "upper", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 1, 0]},
     "elements": [{"type": "rigid_body", "mass": 1.0, "com": [0.2, 0, 0], "inertia": {"ixx": 1e-3, "iyy": 1e-2, "izz": 1e-2}}]},
    {"name": "feather", "parent": "upper", "joint": {"name": "j2", "type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.4, 0, 0]}},
     "elements": [{"type": "rigid_body", "mass": 1e-9, "com": [0.2, 0, 0], "inertia": {"ixx": 1e-12, "iyy": 1e-11, "izz": 1e-11}}]},
    {"name": "lower", "parent": "feather", "joint": {"name": "j3", "type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.4, 0, 0]}},
     "elements": [{"type": "rigid_body", "mass": 0.8, "com": [0.2, 0, 0], "inertia": {"ixx": 1e-3, "iyy": 1e-2, "izz": 1e-2}}]}]})";
  Run r = run("check " + path + " --states 4");
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::Contains("suspicious body 'feather': near-zero mass: 1e-09 kg"));
  CHECK_THAT(r.out, Catch::Contains("recommended: "));
  CHECK(r.out.find("suspicious body 'upper'") == std::string::npos);
  CHECK(r.out.find("suspicious body 'lower'") == std::string::npos);
  r = run("check " + model_path("finger.json") + " --json");
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["suspicious_bodies"].empty());
  CHECK(j["largest_stable_step"]["rk4"].get<double>() > 0);
  std::remove(path.c_str());
}

#ifdef FEMDYN_WITH_SIMBODY
namespace {

// One class of femdyn stress --quick: the verdicts hold and Simbody agrees wherever it runs.
nlohmann::json stress_class(const std::string& klass) {
  const Run r = run("stress --quick --json --class '" + klass + "'");
  INFO(r.out.substr(0, 3000));
  REQUIRE(r.code == 0);
  const auto cases = nlohmann::json::parse(r.out);
  REQUIRE(!cases.empty());
  for (const auto& c : cases) {
    INFO(c["case"] << ": " << c["verdict"]);
    CHECK(c["verdict"].get<std::string>().rfind(c["expected"].get<std::string>(), 0) == 0);
    if (c.contains("simbody_error") && c["simbody_error"].get<double>() >= 0)
      CHECK(c["simbody_error"].get<double>() < 1e-6);
    if (c.contains("positive_definite")) CHECK(c["positive_definite"] == true);
  }
  return cases;
}

}  // namespace

// [long]: not run under the sanitizers (docs/robustness.md#sanitizers).
TEST_CASE("stress springs: 1e1 to 1e5 rad/s, RK4 unstable and BDF stable at 1e5",
          "[stress][long]") {
  const auto springs = stress_class("springs");
  int damped = 0;
  for (const auto& c : springs) {
    if (c["case"] != "spring w=100000 zeta=100") continue;
    ++damped;  // dissipative stiffness: the stiffness bdf cures
    CHECK(c["verdict"].get<std::string>().rfind("stable only with bdf", 0) == 0);
  }
  CHECK(damped == 1);
  for (const auto& c : springs) {
    if (c["case"] != "spring w=100000 zeta=0") continue;
    // Undamped: bdf is stable only by damping it numerically, as femdyn check says.
    CHECK(c["verdict"].get<std::string>().rfind("stiff and undamped", 0) == 0);
    CHECK(c["dt"] == 1e-4);
    CHECK(c["integrators"][0]["integrator"] == "rk4");
    CHECK(c["integrators"][0]["error"] == -1);  // failed: unstable
    CHECK_THAT(c["integrators"][0]["failure"].get<std::string>(),
               Catch::Contains("stability limit"));
    CHECK(c["integrators"][3]["integrator"] == "bdf");
    CHECK(c["integrators"][3]["error"].get<double>() >= 0);
    CHECK(c["integrators"][3]["error"].get<double>() < 1e-2);
  }
}
// [long]: not run under the sanitizers.
TEST_CASE("stress springs: measured stable steps within 5 % of the closed forms",
          "[stress][long]") {
  // Undamped: RK4 ω h ≤ 2√2, semi-implicit Euler ω h < 2. Damped (ζ = 100): the fast real mode
  // λ = −ω(ζ + √(ζ² − 1)) limits RK4 to |λ| h ≤ 2.785 and Euler to the spectral radius of its
  // step, which the linear theory column holds (sim/stability.cpp); both within 5 %.
  for (const auto& c : stress_class("springs")) {
    INFO(c["case"]);
    const std::string name = c["case"];
    const double w = std::stod(name.substr(name.find("w=") + 2)),
                 zeta = std::stod(name.substr(name.find("zeta=") + 5));
    const auto& rk4 = c["integrators"][0];
    const auto& euler = c["integrators"][1];
    const double h_rk4 = rk4["largest_stable_step"], h_euler = euler["largest_stable_step"];
    CHECK(h_rk4 == Approx(rk4["theory_step"].get<double>()).epsilon(0.05));
    CHECK(h_euler == Approx(euler["theory_step"].get<double>()).epsilon(0.05));
    if (zeta == 0) {
      CHECK(h_rk4 * w == Approx(2 * std::sqrt(2.0)).epsilon(0.05));
      CHECK(h_euler * w == Approx(2).epsilon(0.05));
    } else {
      const double lambda = w * (zeta + std::sqrt(zeta * zeta - 1));
      CHECK(h_rk4 * lambda == Approx(2.785).epsilon(0.05));
    }
  }
}
TEST_CASE("stress postures: the slider moves, and every case but the long chain is searched",
          "[stress]") {
  for (const auto& c : stress_class("postures")) {
    INFO(c["case"]);
    CHECK(c["search_note"] == "");
    CHECK(c["integrators"][0]["largest_stable_step"].get<double>() > 0);
    // M^s changes along every motion (the slider is flung out: cond falls by orders).
    CHECK(c["cond_max"].get<double>() > 1.01 * c["cond_min"].get<double>());
  }
  const auto chain = stress_class("size");
  CHECK_THAT(chain[0]["search_note"].get<std::string>(), Catch::Contains("no step search"));
}
TEST_CASE("stress ratios: a mass ratio of 1e6 is ill-conditioned", "[stress]") {
  const auto cases = stress_class("ratios");
  CHECK_THAT(cases[0]["verdict"].get<std::string>(), Catch::Contains("digits"));
}
TEST_CASE("stress speeds: 1e3 rad/s joints and a fast gyroscope", "[stress]") {
  stress_class("speeds");
}
TEST_CASE("stress slender bars with negative lumped rotary inertia", "[stress]") {
  stress_class("slender bars");
}
TEST_CASE("stress flexible: a tube's stiffest mode is its axial chain's 2 c / delta", "[stress]") {
  // 8 parts of Δ = 0.25 m, masses ρAΔ joined by springs EA/Δ: the chain's top mode is
  // 2 √(k/m) = 2 c / Δ, c = √(E/ρ). Undamped it is stiff and undamped; with c = 1e-4 k it is
  // dissipative (ζ = 2 there), which bdf cures.
  const auto cases = stress_class("flexible");
  REQUIRE(cases.size() == 2);
  const double top = 2 * std::sqrt(6.89e10 / 2700) / 0.25;
  CHECK(std::abs(cases[0]["stiffest"].get<double>() / top - 1) < 0.02);
}

TEST_CASE("stress near-singular postures", "[stress]") { stress_class("postures"); }
TEST_CASE("stress a long chain", "[stress]") { stress_class("size"); }
TEST_CASE("stress zero gravity and 1000 g", "[stress]") { stress_class("gravity"); }
TEST_CASE("stress a zero-mass chain end is refused with its message", "[stress]") {
  const auto cases = stress_class("singular");
  CHECK(cases[0]["verdict"] ==
        "refused: stress case 'zero-mass chain end': /bodies/1/joint: the mass matrix M^s is "
        "singular: coordinate 'j2' moves no inertia (a massless chain end, or all its mass on "
        "the joint axis?)");
}
TEST_CASE("stress loops: a dead point named, a redundant loop held, a stiff loop at 2.83/ω",
          "[stress][loops]") {
  const auto cases = stress_class("loops");
  REQUIRE(cases.size() == 4);
  for (const auto& c : cases) {
    INFO(c["case"] << ": " << c["verdict"]);
    const std::string verdict = c["verdict"];
    CHECK(verdict.find("nan") == std::string::npos);
    REQUIRE(c.contains("loops"));
    const auto& loops = c["loops"];
    if (c["case"] == "four-bar at its toggle") {
      // Stretched straight: Φ_q of rank 1, and the bend gravity asks for cannot be held.
      CHECK(verdict.rfind("dead point: ", 0) == 0);
      CHECK_THAT(verdict, Catch::Contains("constraint 'D["));
      CHECK(loops["equations"] == 2);
      CHECK(loops["rank"] == 1);
      continue;
    }
    CHECK(loops["max_position_residual"].get<double>() >= 0);
    CHECK(loops["max_position_residual"].get<double>() < 1e-9);
    CHECK(c["simbody_error"].get<double>() >= 0);           // the twin ran, its loops closed
    if (c["integrators"][0]["error"].get<double>() >= 0) {  // rk4 at the case's step held them
      CHECK(c["integrators"][0]["max_position_residual"].get<double>() >= 0);
      CHECK(c["integrators"][0]["max_position_residual"].get<double>() < 1e-9);
    }
    if (c["case"] == "four-bar near its change point") {
      CHECK(loops["rank"] == 2);
      CHECK(loops["redundant"] == 0);
      CHECK(loops["dead_point_ratio"].get<double>() < 0.05);  // near its flat position
      CHECK(loops["dead_point_ratio"].get<double>() > 0);
      // It stiffens there: the measured RK4 step lies between the smallest linear limit along
      // the motion (held only briefly) and the start's.
      CHECK(loops["stiffest_along"].get<double>() > 10 * c["stiffest"].get<double>());
      const auto& rk4 = c["integrators"][0];
      CHECK(rk4["largest_stable_step"].get<double>() > rk4["theory_step_along"].get<double>());
      CHECK(rk4["largest_stable_step"].get<double>() < rk4["theory_step"].get<double>());
    } else if (c["case"] == "parallelogram closed by a 3-D ball") {
      CHECK(loops["equations"] == 3);
      CHECK(loops["rank"] == 2);
      CHECK(loops["redundant"] == 1);
    } else {
      // The stiff loop: the measured RK4 limit against the constrained linearisation's, and
      // that against the closed form 2√2/ω of its undamped stiffest mode (within 5 %).
      CHECK(c["case"] == "four-bar with a stiff spring");
      const auto& rk4 = c["integrators"][0];
      const double w = c["stiffest"], theory = rk4["theory_step"];
      CHECK(rk4["largest_stable_step"].get<double>() == Approx(theory).epsilon(0.05));
      CHECK(theory * w == Approx(2 * std::sqrt(2.0)).epsilon(0.05));
    }
  }
}
#endif

namespace {

// A from the analytic derivatives against A by central differences, relative to max |A|.
double linearization_mismatch(const Model& m, const VecX& q, const VecX& v, const VecX& tau) {
  Workspace ws(m);
  const Linearization a = linearize(m, ws, q, v, tau),
                      d = difference_linearization(m, ws, q, v, tau);
  REQUIRE(a.status.ok);
  REQUIRE(d.status.ok);
  return rel_error(a.A, d.A, std::max(a.A.cwiseAbs().maxCoeff(), 1e-300));
}

}  // namespace

TEST_CASE("linearize: the analytic A equals the difference A on random trees",
          "[stability][derivatives]") {
  double worst = 0;
  for (unsigned seed = 1; seed <= 6; ++seed)
    for (const int bodies : {2, 7, 12}) {
      INFO("seed " << seed << ", " << bodies << " bodies");
      const Model m = load_text(mixed_tree_json(seed, bodies, seed % 2 ? 0.6 : 0.0, false, true));
      REQUIRE(derivatives_unsupported(m).empty());
      std::mt19937 rng(seed);
      const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1, rng);
      const double e = linearization_mismatch(m, q, v, VecX::Zero(m.n()));
      worst = std::max(worst, e);
      CHECK(e < 1e-6);
    }
  WARN("analytic against difference A, random trees: worst " << worst);
}

TEST_CASE("linearize: the analytic A equals the difference A on closed loops",
          "[stability][derivatives]") {
  // The constrained q̈ at Baumgarte's rate 20 1/s and at 0, on and off the loops.
  double worst = 0;
  for (const char* name : {"five_bar.json", "delta.json", "andrews.json",
                           "finger_fourbar_loop.json", "hand_fourbar_loop.json"}) {
    const Model m = load_model(model_path(name));
    REQUIRE(derivatives_unsupported(m).empty());
    std::mt19937 rng(5);
    VecX q = random_posture(m, rng), v = random_uniform(m.n(), 0.5, rng);
    for (const bool assembled : {false, true}) {
      if (assembled) REQUIRE(assemble_state(m, q, v).assembly.status.ok);
      for (const double omega : {20.0, 0.0}) {
        INFO(name << (assembled ? ", assembled" : ", off the loops") << ", ω = " << omega);
        Workspace ws(m);
        const Linearization a = linearize(m, ws, q, v, VecX::Zero(m.n()), omega),
                            d = difference_linearization(m, ws, q, v, VecX::Zero(m.n()), omega);
        REQUIRE(a.status.ok);
        REQUIRE(d.status.ok);
        const double e = rel_error(a.A, d.A, std::max(a.A.cwiseAbs().maxCoeff(), 1e-300));
        worst = std::max(worst, e);
        CHECK(e < 1e-6);
      }
    }
  }
  WARN("analytic against difference A, closed loops: worst " << worst);
}

TEST_CASE("check's stable steps are the same from the analytic A on the bundled models",
          "[stability][derivatives]") {
  int covered = 0;
  for (const auto& entry : std::filesystem::directory_iterator(model_path(""))) {
    if (entry.path().extension() != ".json") continue;
    const Model m = load_model(entry.path().string());
    if (!derivatives_unsupported(m).empty() || m.n() > 40) continue;
    INFO(entry.path().filename().string());
    ++covered;
    std::mt19937 rng(3);
    const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1, rng);
    Workspace ws(m);
    const Linearization a = linearize(m, ws, q, v, VecX::Zero(m.n()));
    const Linearization d = difference_linearization(m, ws, q, v, VecX::Zero(m.n()));
    for (IntegratorKind kind :
         {IntegratorKind::Rk4, IntegratorKind::Euler, IntegratorKind::Dopri}) {
      const std::optional<double> ha = largest_stable_step(a, kind),
                                  hd = largest_stable_step(d, kind);
      REQUIRE(ha.has_value() == hd.has_value());
      if (ha && std::isfinite(*hd)) CHECK(std::abs(*ha - *hd) <= 1e-3 * *hd);
    }
  }
  CHECK(covered >= 6);
}
