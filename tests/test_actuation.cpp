// Actuation (docs/control.md#actuation): which coordinates an actuator drives, S = I[:, actuated].
// Checked against the model's own words (the defaults and "actuated"), against central
// differences of forward dynamics (the linearisation's B = ∂q̈/∂u), and at every door that runs
// the mechanism under a τ: a τ on an undriven coordinate is refused in one line, never applied.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "compile/actuators.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "sim/control_loop.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A satellite (free joint) carrying an arm: 'shoulder' (driven), 'elbow' (passive unless
// `elbow_driven`) and a 'wrist' spherical joint (driven), under no gravity.
std::string satellite_json(const std::string& elbow_actuated) {
  return R"({"name": "satellite", "gravity": [0, 0, 0], "bodies": [
    {"name": "bus", "parent": "world", "joint": {"name": "base", "type": "free"},
     "elements": [{"type": "rigid_body", "mass": 50, "inertia": {"ixx": 4, "iyy": 5, "izz": 6}}]},
    {"name": "upper", "parent": "bus",
     "joint": {"name": "shoulder", "type": "revolute", "axis": [0, 0, 1],
               "origin": {"xyz": [0.5, 0, 0]}},
     "elements": [{"type": "rigid_body", "mass": 2, "com": [0.3, 0, 0],
                   "inertia": {"ixx": 0.01, "iyy": 0.06, "izz": 0.06}}]},
    {"name": "fore", "parent": "upper",
     "joint": {"name": "elbow", "type": "revolute", "axis": [0, 1, 0],
               "origin": {"xyz": [0.6, 0, 0]})" +
         elbow_actuated + R"(},
     "elements": [{"type": "rigid_body", "mass": 1, "com": [0.25, 0, 0.02],
                   "inertia": {"ixx": 0.005, "iyy": 0.03, "izz": 0.03}}]},
    {"name": "hand", "parent": "fore",
     "joint": {"name": "wrist", "type": "spherical", "origin": {"xyz": [0.5, 0, 0]}},
     "elements": [{"type": "rigid_body", "mass": 0.4, "com": [0.05, 0.01, 0],
                   "inertia": {"ixx": 0.001, "iyy": 0.002, "izz": 0.0025}}]}]})";
}

std::vector<std::string> names_of(const Model& m) {
  std::vector<std::string> out;
  for (int i : m.actuated) out.push_back(m.coordinate_names[i]);
  return out;
}

}  // namespace

TEST_CASE("actuation: every joint but a free one by default, as the model says otherwise",
          "[actuation]") {
  const Model by_default = load_text(satellite_json(""));
  CHECK(by_default.n() == 6 + 1 + 1 + 3);
  // The free joint's 6 rates are the first; the rest are driven.
  CHECK(by_default.actuated == std::vector<int>{6, 7, 8, 9, 10});
  CHECK_FALSE(by_default.fully_actuated());

  const Model passive_elbow = load_text(satellite_json(R"(, "actuated": false)"));
  CHECK(passive_elbow.n_actuated() == 4);
  const auto names = names_of(passive_elbow);
  CHECK(std::find(names.begin(), names.end(), "elbow") == names.end());
  CHECK(std::find(names.begin(), names.end(), "shoulder") != names.end());

  // "actuated": true on the free joint: thrusters push the bus; the same as actuate_free_joints.
  std::string thrusters = satellite_json("");
  thrusters.replace(thrusters.find(R"("type": "free"})"), 15,
                    R"("type": "free", "actuated": true})");
  const Model pushed = load_text(thrusters);
  CHECK(pushed.fully_actuated());
  Model made = load_text(satellite_json(""));
  actuate_free_joints(made);
  CHECK(made.actuated == pushed.actuated);

  // Fixed joints have no motion to drive, and "actuated" is a boolean.
  CHECK_THAT(text_error(R"({"name": "w", "bodies": [{"name": "a", "parent": "world",
      "joint": {"name": "weld", "type": "fixed", "actuated": true},
      "elements": [{"type": "lumped_point", "mass": 1}]}]})"),
             Catch::Contains("/bodies/0/joint/actuated") && Catch::Contains("fixed joint"));
  CHECK_THAT(text_error(satellite_json(R"(, "actuated": 1)")),
             Catch::Contains("/bodies/2/joint/actuated"));
}

TEST_CASE("actuation: the linearisation's B is dq̈/du over the driven coordinates only",
          "[actuation][derivatives]") {
  const Model m = load_text(satellite_json(R"(, "actuated": false)"));
  const int n = m.n();
  VecX q = neutral_posture(m), v(n), tau = VecX::Zero(n);
  q.segment<4>(3) = Eigen::Vector4d(0.9, 0.1, -0.3, 0.2).normalized();  // the bus's attitude
  q[7] = 0.4;                                                           // shoulder
  q[8] = -0.7;                                                          // elbow
  q.tail<4>() = Eigen::Vector4d(0.8, -0.2, 0.4, 0.1).normalized();      // wrist
  for (int i = 0; i < n; ++i) v[i] = 0.3 * std::sin(1.7 * i + 0.2);
  for (int k : m.actuated) tau[k] = 0.5 * std::cos(0.9 * k);
  Workspace ws(m);
  DerivativeWorkspace d(m);
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, tau).ok);
  MatX A, B;
  linearization(m, d, v, A, B);
  REQUIRE(B.rows() == 2 * n);
  REQUIRE(B.cols() == m.n_actuated());
  CHECK(B.topRows(n).isZero(0));
  // Each column against central differences of q̈ under τ ± ε S e_k (an independent route:
  // forward dynamics, not its derivatives).
  const double eps = 1e-6;
  double worst = 0;
  for (int k = 0; k < m.n_actuated(); ++k) {
    VecX up = tau, down = tau;
    up[m.actuated[k]] += eps;
    down[m.actuated[k]] -= eps;
    REQUIRE(forward_dynamics(m, ws, q, v, up).ok);
    const VecX a_up = ws.qdd;
    REQUIRE(forward_dynamics(m, ws, q, v, down).ok);
    const VecX column = (a_up - ws.qdd) / (2 * eps);
    worst = std::max(worst, (B.col(k).tail(n) - column).cwiseAbs().maxCoeff() /
                                std::max(1.0, column.cwiseAbs().maxCoeff()));
  }
  INFO("worst relative difference of B from central differences: " << worst);
  CHECK(worst < 1e-7);  // central differences at ε = 1e-6: O(ε²) truncation, round-off 1e-10
}

TEST_CASE("actuation: a controller's τ on an undriven coordinate is refused, not applied",
          "[actuation][control]") {
  const Model m = load_text(satellite_json(R"(, "actuated": false)"));
  const VecX q0 = neutral_posture(m), v0 = VecX::Zero(m.n());
  ControlLoop loop(m, {.kind = IntegratorKind::Rk4, .fixed = {.dt = 1e-3}},
                   {.mode = ControlMode::ZeroOrderHold, .period = 0.01}, {});
  loop.reset(0, q0, v0);
  VecX tau = VecX::Zero(m.n());
  for (int k : m.actuated) tau[k] = 0.2;
  CHECK(loop.step(tau).ok);  // the driven coordinates: applied
  tau[7] = 0.1;              // the passive elbow
  const Status elbow = loop.step(tau);
  CHECK_FALSE(elbow.ok);
  CHECK_THAT(elbow.message, Catch::Contains("'elbow'") && Catch::Contains("actuated"));
  tau[7] = 0;
  tau[2] = -3;  // the bus's z: a free joint
  const Status bus = loop.step(tau);
  CHECK_FALSE(bus.ok);
  CHECK_THAT(bus.message, Catch::Contains("free joint") && Catch::Contains("'base'"));
  CHECK(unactuated_problem(m, VecX::Zero(m.n())).empty());
}

TEST_CASE("actuation: the CLI's simulate, track, linearize and info honour it",
          "[actuation][cli]") {
  const std::string file = "actuation_satellite.json";
  { std::ofstream(file) << satellite_json(R"(, "actuated": false)"); }
  const std::string zeros = "0,0,0,0,0,0,0,0,0,0,0";
  const Run on_bus = run("simulate " + file + " --t-end 0.01 --tau 1," + zeros.substr(2) + " 2>&1");
  CHECK(on_bus.code != 0);
  CHECK_THAT(on_bus.out, Catch::Contains("--tau") && Catch::Contains("'base"));
  const Run on_shoulder =
      run("simulate " + file + " --t-end 0.01 --tau 0,0,0,0,0,0,1,0,0,0,0 2>&1");
  CHECK(on_shoulder.code == 0);
  const Run tracked = run("track " + file + " --to 0 --actuated-base 2>&1");
  CHECK(tracked.code == 1);
  CHECK_THAT(tracked.out, Catch::Contains("'elbow'") && Catch::Contains("not actuated"));
  const Run lin = run("linearize " + file + " --json");
  REQUIRE(lin.code == 0);
  CHECK_THAT(lin.out,
             Catch::Contains(R"("inputs": ["shoulder", "wrist.wx", "wrist.wy", "wrist.wz"])"));
  const Run info = run("info " + file);
  CHECK_THAT(info.out, Catch::Contains("actuated (n_a = 4): shoulder wrist.wx wrist.wy wrist.wz"));
  std::remove(file.c_str());
}
