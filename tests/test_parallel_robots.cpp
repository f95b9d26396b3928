// Parallel robots closed by loop constraints (core/loops/): the five-bar (models/five_bar.json)
// and the Delta robot (models/delta.json) against their closed-form kinematics written here,
// independently of femdyn (the five-bar's forward kinematics as the intersection of two circles,
// the Delta's inverse kinematics arm by arm), their constrained dynamics against the equations
// it solves, and a short `femdyn simulate` of each; and the four-bar finger closed by a
// constraint (models/finger_fourbar_loop.json) against the same finger closed by the four_bar
// coupling law (models/finger_fourbar.json): the same motion.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "tests/loop_checks.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;

namespace {

// Index of a configuration entry (q) by name.
int q_index(const Model& m, const std::string& name) {
  for (int i = 0; i < m.n_q(); ++i)
    if (m.configuration_names[i] == name) return i;
  FAIL("no coordinate " << name);
  return -1;
}

int v_index(const Model& m, const std::string& name) {
  for (int i = 0; i < m.n(); ++i)
    if (m.coordinate_names[i] == name) return i;
  FAIL("no rate " << name);
  return -1;
}

FrameKinematics frame_at(const Model& m, Workspace& ws, const VecX& q, const std::string& name) {
  const int f = find_frame(m, name);
  REQUIRE(f >= 0);
  FrameKinematics k;
  frame_kinematics(m, ws, q, VecX::Zero(m.n()), f, FrameAxes::LocalWorldAligned, k);
  return k;
}

// The five-bar's geometry (models/five_bar.json): base joints at (∓b/2, 0), proximal links l1,
// distal links l2, in the x-y plane.
constexpr double kBase = 0.2, kL1 = 0.2, kL2 = 0.3;

// Forward kinematics of the five-bar: the end effector C from the base angles, the intersection
// of the circles of radius l2 about the elbows B1, B2 on the side to the left of B1 → B2 (the
// working mode with the end effector above the base).
Vec3 five_bar_tip(double theta1, double theta2) {
  const Eigen::Vector2d b1(-kBase / 2 + kL1 * std::cos(theta1), kL1 * std::sin(theta1));
  const Eigen::Vector2d b2(kBase / 2 + kL1 * std::cos(theta2), kL1 * std::sin(theta2));
  const Eigen::Vector2d d = b2 - b1;
  const double len = d.norm(), h = std::sqrt(kL2 * kL2 - len * len / 4);
  const Eigen::Vector2d c = b1 + d / 2 + h * Eigen::Vector2d(-d.y(), d.x()) / len;
  return {c.x(), c.y(), 0};
}

// The Delta's geometry (models/delta.json): base side f, platform side e, arm rf, forearm re.
constexpr double kF = 0.4573, kE = 0.115, kRf = 0.112, kRe = 0.232;

// Inverse kinematics of the Delta: arm k's angle below the base plane for the platform centre at
// p (elbows out). In arm k's plane (the world turned by −2πk/3 about z) the arm's pivot is at
// (0, −R, 0) with R = f/(2√3), its elbow at (0, −R − rf cos θ, −rf sin θ), and the forearm's end
// on the platform at (x, y − r, z) with r = e/(2√3); |elbow − end| = re gives
// Y cos θ + z sin θ = K, Y = y − r + R, K = (re² − x² − Y² − z² − rf²) / (2 rf).
double delta_arm_angle(const Vec3& p, int k) {
  const double phi = 2 * std::numbers::pi * k / 3, c = std::cos(phi), s = std::sin(phi);
  const double x = c * p.x() + s * p.y(), y = -s * p.x() + c * p.y(), z = p.z();
  const double R = kF / (2 * std::sqrt(3.0)), r = kE / (2 * std::sqrt(3.0));
  const double Y = y - r + R;
  const double K = (kRe * kRe - x * x - Y * Y - z * z - kRf * kRf) / (2 * kRf);
  return std::atan2(z, Y) + std::acos(K / std::hypot(Y, z));
}

// Φ_q q̈ + Φ̇_q v = 0 and inverse dynamics of q̈ giving back τ + Φ_qᵀ λ, at an assembled state
// with a velocity projected onto the loops.
void check_constrained_dynamics(const Model& m, VecX q, unsigned seed) {
  std::mt19937 rng(seed);
  VecX v = random_uniform(m.n(), 1.0, rng);
  const StateAssembly s = assemble_state(m, q, v);
  REQUIRE(s.assembly.status.ok);
  CHECK(check_constrained_equations(m, q, v, random_uniform(m.n(), 0.5, rng)) == m.constraint_rows);
}

// `femdyn simulate` of a bundled model for 0.2 s at tight tolerances: its loops line and report.
Json simulate_json(const std::string& model) {
  const Run r = run("simulate " + model_path(model) +
                    " --t-end 0.2 --integrator dopri --rtol 1e-10 --atol 1e-10 --json");
  REQUIRE(r.code == 0);
  return Json::parse(r.out);
}

}  // namespace

TEST_CASE("five-bar: assembly, 2 DOF, and the tip on the circles' intersection",
          "[loops][parallel]") {
  const Model m = load_model(model_path("five_bar.json"));
  REQUIRE(m.n() == 4);
  REQUIRE(m.constraint_rows == 2);
  const int t1 = q_index(m, "theta1"), t2 = q_index(m, "theta2");
  Workspace ws(m);
  // At the model's initial values the loop is closed already.
  VecX q = neutral_posture(m), v = VecX::Zero(m.n());
  CHECK(std::abs(q[t1] - 115 * std::numbers::pi / 180) < 1e-15);
  StateAssembly s = assemble_state(m, q, v);
  REQUIRE(s.assembly.status.ok);
  CHECK(s.assembly.residual < 1e-12);
  CHECK(s.assembly.rank == 2);
  CHECK(s.assembly.redundant == 0);
  CHECK(m.n() - s.assembly.rank == 2);
  CHECK((frame_at(m, ws, q, "tip").p - Vec3(0.012561462191071179, 0.4074417016001085, 0)).norm() <
        1e-12);
  // From disturbed postures: Newton closes the loop, and the tip is where the closed form puts it
  // for the base angles it ends with.
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    q = neutral_posture(m) + random_uniform(m.n(), 0.1, rng);
    v = VecX::Zero(m.n());
    s = assemble_state(m, q, v);
    REQUIRE(s.assembly.status.ok);
    CHECK(s.assembly.residual < 1e-12);
    CHECK(s.assembly.redundant == 0);
    const Vec3 closed_form = five_bar_tip(q[t1], q[t2]);
    CAPTURE(trial, q.transpose(), closed_form.transpose());
    // (|Φ| ≤ 1e-12 at the end of assembly: the two tips agree to that)
    CHECK((frame_at(m, ws, q, "tip").p - closed_form).norm() < 1e-11);
    CHECK((frame_at(m, ws, q, "tip_right").p - closed_form).norm() < 1e-11);
  }
  check_constrained_dynamics(m, neutral_posture(m), 3);
}

TEST_CASE("Delta robot: assembly, 3 DOF, a translating platform, inverse kinematics",
          "[loops][parallel]") {
  const Model m = load_model(model_path("delta.json"));
  REQUIRE(m.n() == 9);  // 3 arms and the platform's free joint (6 rates, 7 coordinates)
  REQUIRE(m.n_q() == 10);
  REQUIRE(m.constraint_rows == 6);
  Workspace ws(m);
  VecX q = neutral_posture(m), v = VecX::Zero(m.n());
  StateAssembly s = assemble_state(m, q, v);
  REQUIRE(s.assembly.status.ok);
  CHECK(s.assembly.residual < 1e-12);
  CHECK(s.assembly.rank == 6);
  CHECK(s.assembly.redundant == 0);
  CHECK(m.n() - s.assembly.rank == 3);
  const Vec3 start(0.03, -0.02, -0.19);
  CHECK((frame_at(m, ws, q, "tcp").p - start).norm() < 1e-14);
  for (int k = 0; k < 3; ++k)
    CHECK(std::abs(q[q_index(m, "theta" + std::to_string(k + 1))] - delta_arm_angle(start, k)) <
          1e-14);
  // From disturbed postures (the platform turned too): Newton closes the loops onto a platform
  // that translates only, whose position gives back each arm's angle by inverse kinematics.
  std::mt19937 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    q = integrate_posture(m, neutral_posture(m), random_uniform(m.n(), 0.03, rng));
    v = VecX::Zero(m.n());
    s = assemble_state(m, q, v);
    REQUIRE(s.assembly.status.ok);
    CHECK(s.assembly.residual < 1e-12);
    CHECK(s.assembly.redundant == 0);
    const FrameKinematics tcp = frame_at(m, ws, q, "tcp");
    CAPTURE(trial, q.transpose(), tcp.p.transpose());
    CHECK((tcp.R - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-11);
    for (int k = 0; k < 3; ++k)
      CHECK(std::abs(q[q_index(m, "theta" + std::to_string(k + 1))] - delta_arm_angle(tcp.p, k)) <
            1e-11);
  }
  check_constrained_dynamics(m, neutral_posture(m), 4);
}

TEST_CASE("five-bar and Delta simulate: loops closed, energy kept", "[loops][parallel][cli]") {
  for (const auto& [model, rank] : {std::pair{"five_bar.json", 2}, std::pair{"delta.json", 6}}) {
    INFO(model);
    const Json j = simulate_json(model);
    CHECK(j["loops"]["rank"] == rank);
    CHECK(j["loops"]["redundant"] == 0);
    CHECK(j["loops"]["assembly_residual"].get<double>() < 1e-12);
    CHECK(j["loops"]["max_position_residual"].get<double>() < 1e-9);
    CHECK(j["loops"]["max_velocity_residual"].get<double>() < 1e-9);
    // Gravity only, no dampers: the energy is kept (a drift of ~1e-11 of it measured).
    CHECK(j["energy_balance_relative"].get<double>() < 1e-8);
  }
  const Run r = run("simulate " + model_path("five_bar.json") + " --t-end 0.05");
  REQUIRE(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("loops: 2 constraint equations, rank 2 (0 redundant)"));
}

TEST_CASE("four-bar finger: the loop closed by a constraint moves as the four_bar law",
          "[loops][parallel][couplings]") {
  // Both under gravity across the flexion plane and constant joint torques, from the same start.
  const auto with_gravity = [](const std::string& file) {
    Json j;
    std::ifstream(model_path(file)) >> j;
    j["gravity"] = {0, -1.0, -0.5};
    return load_text(j.dump());
  };
  const Model law = with_gravity("finger_fourbar.json");
  const Model loop = with_gravity("finger_fourbar_loop.json");
  REQUIRE(law.n() == 3);
  REQUIRE(loop.n() == 5);
  REQUIRE(loop.constraint_rows == 2);
  for (int i = 0; i < 3; ++i) REQUIRE(law.coordinate_names[i] == loop.coordinate_names[i]);
  const int dip = v_index(loop, "dip"), coupler = v_index(loop, "coupler");
  REQUIRE((dip == 3 && coupler == 4));

  const VecX q_law = (VecX(3) << 0.1, 0.3, 0.5).finished();
  const VecX v_law = (VecX(3) << 0.5, -1.0, 1.0).finished();
  // The loop model's start: the same three coordinates held, dip and the coupler assembled, and
  // their rates from Φ_q v = 0.
  VecX q_loop(5), v_loop(5);
  q_loop << q_law, 0.5 * 2 / 3, 0;
  Workspace ws(loop);
  LoopWorkspace lws(loop);
  const AssemblyReport a = assemble(loop, ws, lws.k, q_loop, {.held = {0, 1, 2}});
  REQUIRE(a.status.ok);
  REQUIRE(a.residual < 1e-14);
  REQUIRE(a.rank == 2);
  CHECK((q_loop.head(3) - q_law).norm() == 0);
  v_loop << v_law, 0, 0;
  constraint_kinematics(loop, ws, q_loop, v_loop, lws.k);
  const Eigen::Matrix2d Jd = lws.k.J.rightCols(2);
  v_loop.tail(2) = Jd.partialPivLu().solve(-lws.k.J.leftCols(3) * v_law);
  constraint_kinematics(loop, ws, q_loop, v_loop, lws.k);
  REQUIRE((lws.k.J * v_loop).cwiseAbs().maxCoeff() < 1e-14);

  // The same q̈ at the start (the rod's inertia, gravity and the torques through the law's
  // derivatives on one side, through the constraint force on the other).
  const VecX tau_law = (VecX(3) << 2e-4, -1e-4, 5e-5).finished();
  const VecX tau_loop = (VecX(5) << tau_law, 0, 0).finished();
  Workspace ws_law(law);
  REQUIRE(forward_dynamics(law, ws_law, q_law, v_law, tau_law).ok);
  const VecX qdd_law = ws_law.qdd;
  REQUIRE(constrained_forward_dynamics(loop, ws, lws, q_loop, v_loop, tau_loop, 0).ok);
  CAPTURE(qdd_law.transpose(), ws.qdd.transpose());
  CHECK(rel_error(ws.qdd.head(3), qdd_law, 1) < 1e-12);

  const auto torques = [](int n) {
    return [n](double, VecX& tau) {
      tau = VecX::Zero(n);
      tau.head(3) << 2e-4, -1e-4, 5e-5;  // N m on abduction, mcp, pip (as tau_law)
    };
  };
  AdaptiveOptions o;
  o.rtol = 1e-12;
  o.atol = 1e-12;
  auto run_law = make_integrator(law, {.kind = IntegratorKind::Dopri, .adaptive = o}, torques(3));
  auto run_loop = make_integrator(loop, {.kind = IntegratorKind::Dopri, .adaptive = o}, torques(5));
  const double t_end = 0.5;
  run_law->reset(0, q_law, v_law, t_end);
  run_loop->reset(0, q_loop, v_loop, t_end);
  double worst_angle = 0, worst_rate = 0, worst_tip = 0;
  double pip_low = q_law[2], pip_high = q_law[2];
  for (int k = 1; k <= 50; ++k) {
    const double t = t_end * k / 50;
    REQUIRE(run_law->advance_to(t).ok);
    REQUIRE(run_loop->advance_to(t).ok);
    const VecX ql = run_law->q(), qc = run_loop->q();
    worst_angle = std::max(worst_angle, (qc.head(3) - ql).cwiseAbs().maxCoeff());
    worst_rate =
        std::max(worst_rate, (run_loop->qd().head(3) - run_law->qd()).cwiseAbs().maxCoeff());
    // The distal joint too: the fingertip, which it moves, in both models.
    worst_tip = std::max(
        worst_tip, (frame_at(law, ws_law, ql, "tip").p - frame_at(loop, ws, qc, "tip").p).norm());
    pip_low = std::min(pip_low, ql[2]);
    pip_high = std::max(pip_high, ql[2]);
  }
  CAPTURE(worst_angle, worst_rate, worst_tip, pip_low, pip_high);
  // The linkage moves well through the PIP's range [0, 1.75].
  CHECK(pip_low > 0);
  CHECK(pip_high < 1.75);
  CHECK(pip_high - pip_low > 0.5);
  // Both are integrated by dopri to rtol = atol = 1e-12, and their difference is of the order of
  // those global errors: 8e-12 rad, 1.4e-10 rad/s and 4e-13 m measured. The bounds leave a factor
  // of about 100 for other compilers and platforms; a modelling difference (a wrong lever, the
  // coupler's mass on another point) shows at 1e-4 and more.
  CHECK(worst_angle < 1e-9);
  CHECK(worst_rate < 1e-8);
  CHECK(worst_tip < 1e-10);
}

TEST_CASE("four-bar hand: the plugin's closure by constraints moves as its four_bar laws",
          "[loops][parallel][couplings]") {
  // models/hand_fourbar_loop.json is models/hand_fourbar.json with "closure": "constraint": the
  // same 17 coordinates, plus each finger's dip and coupler joints, closed by 5 planar balls.
  const Model law = load_model(model_path("hand_fourbar.json"));
  const Model loop = load_model(model_path("hand_fourbar_loop.json"));
  REQUIRE(law.n() == 17);
  REQUIRE(loop.n() == 27);
  REQUIRE(loop.constraint_rows == 10);
  std::vector<int> shared, dependent;  // the loop's rates that the law model has, and the rest
  for (int i = 0; i < loop.n(); ++i) {
    const auto& names = law.coordinate_names;
    (std::find(names.begin(), names.end(), loop.coordinate_names[i]) != names.end() ? shared
                                                                                    : dependent)
        .push_back(i);
  }
  REQUIRE(shared.size() == 17);
  Workspace ws_law(law), ws(loop);
  LoopWorkspace lws(loop);
  std::mt19937 rng(5);
  for (int k = 0; k < 3; ++k) {
    INFO("state " << k);
    const VecX q_law = random_posture(law, rng), v_law = random_uniform(17, 1, rng),
               tau_law = random_uniform(17, 1e-3, rng);
    // The loop model at the same 17 coordinates, each dip and coupler assembled by continuation
    // from the closed posture q = 0 (Newton from a far guess may not find the branch), their
    // rates from Φ_q v = 0.
    VecX q = VecX::Zero(27), v = VecX::Zero(27), tau = VecX::Zero(27);
    for (int step = 1; step <= 10; ++step) {
      for (int i = 0; i < 17; ++i) q[shared[i]] = q_law[i] * step / 10;
      const AssemblyReport assembled = assemble(loop, ws, lws.k, q, {.held = shared});
      INFO("step " << step << ": " << assembled.status.message);
      REQUIRE(assembled.status.ok);
    }
    for (int i = 0; i < 17; ++i) v[shared[i]] = v_law[i], tau[shared[i]] = tau_law[i];
    constraint_kinematics(loop, ws, q, v, lws.k);
    MatX Jd(10, 10);
    for (int c = 0; c < 10; ++c) Jd.col(c) = lws.k.J.col(dependent[c]);
    const VecX vd = Jd.partialPivLu().solve(-lws.k.J * v);
    for (int c = 0; c < 10; ++c) v[dependent[c]] = vd[c];
    REQUIRE(forward_dynamics(law, ws_law, q_law, v_law, tau_law).ok);
    const VecX qdd_law = ws_law.qdd;
    REQUIRE(constrained_forward_dynamics(loop, ws, lws, q, v, tau, 0).ok);
    VecX qdd_shared(17);
    for (int i = 0; i < 17; ++i) qdd_shared[i] = ws.qdd[shared[i]];
    CAPTURE(qdd_law.transpose(), qdd_shared.transpose());
    CHECK(rel_error(qdd_shared, qdd_law) < 1e-9);
    for (const char* tip : {"index_tip", "little_tip", "thumb_tip"})
      CHECK((frame_at(law, ws_law, q_law, tip).p - frame_at(loop, ws, q, tip).p).norm() < 1e-12);
  }
}

TEST_CASE("four-bar finger: the plugin's closure by a constraint is finger_fourbar_loop.json",
          "[loops][parallel]") {
  // The plugin's generated linkage against the hand-written model file: the same equations.
  Json j;
  std::ifstream(model_path("finger_fourbar.json")) >> j;
  j["params"]["coupling"]["closure"] = "constraint";
  const Model generated = load_text(j.dump());
  const Model file = load_model(model_path("finger_fourbar_loop.json"));
  REQUIRE(generated.coordinate_names == file.coordinate_names);
  REQUIRE(generated.constraint_rows == file.constraint_rows);
  Workspace wg(generated), wf(file);
  LoopWorkspace lg(generated), lf(file);
  VecX q = (VecX(5) << 0.1, 0.3, 0.5, 0.5 * 2 / 3, 0).finished(), v = VecX::Zero(5);
  REQUIRE(assemble(file, wf, lf.k, q, {.held = {0, 1, 2}}).status.ok);
  v << 0.5, -1.0, 1.0, 0, 0;
  const VecX tau = (VecX(5) << 2e-4, -1e-4, 5e-5, 0, 0).finished();
  REQUIRE(constrained_forward_dynamics(file, wf, lf, q, v, tau, 20).ok);
  REQUIRE(constrained_forward_dynamics(generated, wg, lg, q, v, tau, 20).ok);
  CHECK(rel_error(lg.k.phi, lf.k.phi, 1e-3) < 1e-12);
  CHECK(rel_error(lg.k.J, lf.k.J) < 1e-12);
  CHECK(rel_error(wg.qdd, wf.qdd) < 1e-10);
}
