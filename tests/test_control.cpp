// The controller in the loop (sim/control_loop.hpp) against independent references: a PD law
// evaluated in f is the joint spring–damper it mimics, ZOH tends to the per-evaluation motion at
// order 1 in the period T, E(t) − E(0) = W(t) under the controller, an adaptive run in ZOH mode
// matches rk4 at a small step, failures name the controller, and a period allocates nothing.
#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

#include "sim/control_loop.hpp"
#include "tests/helpers.hpp"
#include "validation/alloc_counter.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

IntegratorOptions fixed(IntegratorKind kind, double dt) {
  return {.kind = kind, .fixed = {.dt = dt}};
}

IntegratorOptions adaptive(IntegratorKind kind, double rtol, double atol) {
  return {.kind = kind, .adaptive = {.rtol = rtol, .atol = atol}};
}

ControlLoopOptions loop(ControlMode mode, double T) { return {.mode = mode, .period = T}; }

// τ = −K_p (q − q_d) − K_d v, gains per coordinate.
Control pd(VecX kp, VecX kd, VecX q_d) {
  return [kp = std::move(kp), kd = std::move(kd), q_d = std::move(q_d)](double, const VecX& q,
                                                                        const VecX& v, VecX& tau) {
    tau = -kp.cwiseProduct(q - q_d) - kd.cwiseProduct(v);
  };
}

// A PD law on the finger (no gravity, grams and centimetres): gains from the diagonal of M^s at
// the target, ω = 30 rad/s, ζ = 0.3, so that the motion rings for a few tenths of a second.
struct FingerCase {
  Model m = load_model(model_path("finger.json"));
  VecX q0 = VecX::Zero(4), qd0 = VecX::Zero(4), q_d = VecX(4);
  Control u;
  FingerCase() {
    q_d << 0.2, 0.8, 0.6, 0.4;
    qd0 << 1, -2, 0.5, 3;
    Workspace ws(m);
    mass_matrix(m, ws, q_d);
    const VecX Md = ws.Ms.diagonal();
    constexpr double w = 30, zeta = 0.3;
    u = pd(w * w * Md, 2 * zeta * w * Md, q_d);
  }
};

// (q, q̇) after `periods` periods of T.
VecX run_to(ControlLoop& c, const VecX& q0, const VecX& qd0, int periods) {
  c.reset(0, q0, qd0);
  for (int k = 0; k < periods; ++k) {
    const Status st = c.step();
    INFO(st.message);
    REQUIRE(st.ok);
  }
  return c.integrator().y().head(2 * c.integrator().motion().n());
}

}  // namespace

TEST_CASE("a PD law evaluated in f is the joint spring-damper it mimics", "[control]") {
  constexpr double k = 40, c = 0.9, g = 9.81;
  const Model spring = load_text(arm_json(k, c, g)), bare = load_text(arm_json(0, 0, g));
  const VecX q0 = VecX::Constant(1, 0.4), qd0 = VecX::Constant(1, -1.0);
  auto passive = make_integrator(spring, fixed(IntegratorKind::Rk4, 1e-3));
  ControlLoop controlled(bare, fixed(IntegratorKind::Rk4, 1e-3),
                         loop(ControlMode::PerEvaluation, 0.01),
                         pd(VecX::Constant(1, k), VecX::Constant(1, c), VecX::Zero(1)));
  passive->reset(0, q0, qd0);
  controlled.reset(0, q0, qd0);
  double diff = 0, travel = 0;
  for (int i = 1; i <= 300; ++i) {  // 3 s, several periods of ω = √40 rad/s
    REQUIRE(passive->advance_to(0.01 * i).ok);
    REQUIRE(controlled.step().ok);
    REQUIRE(controlled.t() == passive->t());
    diff = std::max(
        diff, (controlled.integrator().y().head(2) - passive->y().head(2)).cwiseAbs().maxCoeff());
    travel = std::max(travel, std::abs(passive->q()[0] - q0[0]));
  }
  INFO("max |(q, q̇) controlled − spring-damper| = " << diff << ", travel " << travel << " rad");
  CHECK(travel > 0.3);  // the motion is not trivial
  CHECK(diff < 1e-10);
  CHECK(controlled.controller_calls() == 0);  // (ZOH samples: none in this mode)
  CHECK(controlled.integrator().motion().evaluations() == 4 * 3000);
}

TEST_CASE("ZOH tends to the per-evaluation motion at order 1 in T", "[control]") {
  const FingerCase f;
  // The plant's own error made negligible: rk4 at 1e-4 s, a divisor of every T.
  const IntegratorOptions rk4 = fixed(IntegratorKind::Rk4, 1e-4);
  constexpr double t_end = 0.4;
  ControlLoop reference(f.m, rk4, loop(ControlMode::PerEvaluation, 0.01), f.u);
  const VecX x_ref = run_to(reference, f.q0, f.qd0, 40);
  double e[3];
  for (int i = 0; i < 3; ++i) {
    const double T = 0.002 / (1 << i);
    ControlLoop zoh(f.m, rk4, loop(ControlMode::ZeroOrderHold, T), f.u);
    const VecX x = run_to(zoh, f.q0, f.qd0, static_cast<int>(std::lround(t_end / T)));
    REQUIRE(std::abs(zoh.t() - t_end) < 1e-12);
    CHECK(zoh.controller_calls() == std::lround(t_end / T));
    e[i] = (x - x_ref).cwiseAbs().maxCoeff();
  }
  INFO("errors at T = 2, 1, 0.5 ms: " << e[0] << ", " << e[1] << ", " << e[2]);
  CHECK(e[2] > 1e-3);  // the sampling matters at these periods
  CHECK(e[0] / e[1] == Approx(2).margin(0.2));
  CHECK(e[1] / e[2] == Approx(2).margin(0.2));
}

TEST_CASE("E(t) − E(0) = W(t) with the controller's tau, in both modes", "[control]") {
  const FingerCase f;
  constexpr double tol = 1e-10;
  for (ControlMode mode : {ControlMode::PerEvaluation, ControlMode::ZeroOrderHold}) {
    for (IntegratorKind kind : {IntegratorKind::Dopri, IntegratorKind::Bdf}) {
      ControlLoop c(f.m, adaptive(kind, tol, tol), loop(mode, 0.005), f.u);
      c.reset(0, f.q0, f.qd0);
      Motion& motion = c.integrator().motion();
      const double E0 = motion.energy_at(c.integrator().y().data()).total();
      double balance = 0, work = 0, scale = std::abs(E0);
      for (int k = 0; k < 60; ++k) {
        REQUIRE(c.step().ok);
        const Energy E = motion.energy_at(c.integrator().y().data());
        balance = std::max(balance, std::abs(E.total() - E0 - c.integrator().work()));
        work = std::max(work, std::abs(c.integrator().work()));
        scale = std::max({scale, E.kinetic, std::abs(E.total())});
      }
      INFO((mode == ControlMode::ZeroOrderHold ? "ZOH " : "per evaluation ")
           << integrator_name(kind) << ": |E − E0 − W| ≤ " << balance << " J, |W| up to " << work
           << " J, scale " << scale << " J");
      CHECK(work > 0.1 * scale);  // the controller did real work
      CHECK(balance <= (kind == IntegratorKind::Bdf ? 1000 : 100) * tol * scale);
    }
  }
}

TEST_CASE("an adaptive run in ZOH mode matches rk4 at a small step", "[control]") {
  const FingerCase f;
  constexpr double T = 0.01;
  ControlLoop rk4(f.m, fixed(IntegratorKind::Rk4, 1e-4), loop(ControlMode::ZeroOrderHold, T), f.u);
  const VecX x_ref = run_to(rk4, f.q0, f.qd0, 30);
  for (IntegratorKind kind : {IntegratorKind::Dopri, IntegratorKind::Bdf}) {
    ControlLoop c(f.m, adaptive(kind, 1e-10, 1e-12), loop(ControlMode::ZeroOrderHold, T), f.u);
    const VecX x = run_to(c, f.q0, f.qd0, 30);
    const double err = (x - x_ref).cwiseAbs().maxCoeff();
    INFO(integrator_name(kind) << ": max |(q, q̇) − rk4's| = " << err << " after "
                               << c.integrator().stats().steps << " steps");
    CHECK(c.t() == Approx(0.3).epsilon(1e-14));
    CHECK(err < 1e-7);
    CHECK(c.integrator().stats().steps >= 30);  // (counted across the restarts)
  }
}

TEST_CASE("a bad controller is named: wrong size, NaN, and its exception", "[control]") {
  const FingerCase f;
  for (IntegratorKind kind : {IntegratorKind::Rk4, IntegratorKind::Dopri}) {
    const IntegratorOptions o =
        kind == IntegratorKind::Rk4 ? fixed(kind, 1e-3) : adaptive(kind, 1e-8, 1e-10);
    for (ControlMode mode : {ControlMode::PerEvaluation, ControlMode::ZeroOrderHold}) {
      INFO(integrator_name(kind) << (mode == ControlMode::ZeroOrderHold ? " ZOH" : " per eval"));
      ControlLoop short_tau(f.m, o, loop(mode, 0.01),
                            [](double, const VecX&, const VecX&, VecX& tau) { tau.resize(3); });
      short_tau.reset(0, f.q0, f.qd0);
      Status st = short_tau.step();
      CHECK_FALSE(st.ok);
      CHECK_THAT(st.message, Catch::Contains("tau has 3 entries, expected 4"));
      ControlLoop nan(f.m, o, loop(mode, 0.01), [](double t, const VecX&, const VecX&, VecX& tau) {
        tau.setZero();
        if (t >= 0.02) tau[2] = std::nan("");
      });
      nan.reset(0, f.q0, f.qd0);
      do st = nan.step();
      while (st.ok && nan.t() < 1);
      CHECK_FALSE(st.ok);
      CHECK_THAT(st.message, Catch::Contains("tau is NaN or Inf"));
      CHECK(nan.t() <= 0.03);
      ControlLoop throws(f.m, o, loop(mode, 0.01), [](double t, const VecX&, const VecX&, VecX&) {
        if (t >= 0.02) throw std::runtime_error("sensor lost");
      });
      throws.reset(0, f.q0, f.qd0);
      CHECK_THROWS_WITH(
          [&] {
            while (throws.t() < 1 && throws.step().ok) {
            }
          }(),
          "sensor lost");
    }
  }
  ControlLoop given(f.m, fixed(IntegratorKind::Rk4, 1e-3), loop(ControlMode::ZeroOrderHold, 0.01));
  given.reset(0, f.q0, f.qd0);
  const Status st = given.step(VecX::Constant(4, std::nan("")));
  CHECK_FALSE(st.ok);
  CHECK_THAT(st.message, Catch::Contains("tau is NaN or Inf (abduction)"));
  CHECK(given.t() == 0);
}

TEST_CASE("a control period allocates nothing (rk4, dopri, bdf, both modes)",
          "[control][hot-path]") {
  if (!alloc_counter::kAvailable) {
    WARN("skipped under sanitizers: ASan owns malloc, nothing is counted");
    return;
  }
  const FingerCase f;
  for (ControlMode mode : {ControlMode::PerEvaluation, ControlMode::ZeroOrderHold}) {
    for (const IntegratorOptions& o :
         {fixed(IntegratorKind::Rk4, 1e-3), adaptive(IntegratorKind::Dopri, 1e-8, 1e-10),
          adaptive(IntegratorKind::Bdf, 1e-8, 1e-10)}) {
      INFO((mode == ControlMode::ZeroOrderHold ? "ZOH " : "per evaluation ")
           << integrator_name(o.kind));
      ControlLoop c(f.m, o, loop(mode, 0.005), f.u);
      c.reset(0, f.q0, f.qd0);
      REQUIRE(c.step().ok);  // warm-up
      alloc_counter::start();
      bool ok = true;
      for (int k = 0; k < 20; ++k) ok = ok && c.step().ok;
      const long mallocs = alloc_counter::stop();
      CHECK(ok);
      CHECK(mallocs == 0);
    }
  }
}

TEST_CASE("a discontinuous controller in f costs dopri rejected steps, held, far fewer",
          "[control]") {
  // Bang-bang on the abduction joint: τ₀ = −τ_max sign(q₀ − q_d), which switches as q₀ crosses
  // q_d. In f the switch lies inside steps, which the error test rejects until they are short;
  // held, τ is constant over every period and the method restarts at each sample (a few steps
  // are rejected there, the first after a jump taken as long as the last before it).
  const FingerCase f;
  const Control bang = [](double, const VecX& q, const VecX&, VecX& tau) {
    tau.setZero();
    tau[0] = q[0] > 0.1 ? -2e-3 : 2e-3;
  };
  long rejected[2];
  int i = 0;
  for (ControlMode mode : {ControlMode::PerEvaluation, ControlMode::ZeroOrderHold}) {
    ControlLoop c(f.m, adaptive(IntegratorKind::Dopri, 1e-8, 1e-10), loop(mode, 0.01), bang);
    c.reset(0, f.q0, VecX::Zero(4));
    for (int k = 0; k < 50; ++k) REQUIRE(c.step().ok);
    rejected[i++] = c.integrator().stats().rejected;
  }
  INFO("rejected steps: in f " << rejected[0] << ", held " << rejected[1]);
  CHECK(rejected[0] >= 5 * std::max(rejected[1], 1L));
}

TEST_CASE("on a spherical joint the controller sees q (n_q = 4) and v (n = 3)", "[control]") {
  // A spherical pendulum (a 1 kg body 1 m below the ball) under a damping controller τ = −c v; the
  // quaternion makes y hold chart coordinates, which the adaptive method moves, restarting, as the
  // ball turns.
  const Model m = load_text(R"({"name": "ball", "gravity": [0, 0, -9.81], "bodies": [
    {"name": "bob", "parent": "world", "joint": {"name": "ball", "type": "spherical"},
     "elements": [{"type": "rigid_body", "mass": 1.0, "com": [0, 0, -1], "inertia": {"ixx": 0.01,
       "iyy": 0.01, "izz": 0.02, "ixy": 0, "ixz": 0, "iyz": 0}}]}]})");
  REQUIRE(m.n_q() == 4);
  REQUIRE(m.n() == 3);
  VecX q0(4), v0(3);
  q0 << std::cos(0.6), std::sin(0.6), 0, 0;  // tilted 1.2 rad about x
  v0 << 0, 1.5, 4.0;                         // and spinning about the vertical
  for (ControlMode mode : {ControlMode::PerEvaluation, ControlMode::ZeroOrderHold}) {
    for (const IntegratorOptions& o :
         {fixed(IntegratorKind::Rk4, 1e-3), adaptive(IntegratorKind::Dopri, 1e-10, 1e-12)}) {
      INFO((mode == ControlMode::ZeroOrderHold ? "ZOH " : "per evaluation ")
           << integrator_name(o.kind));
      bool sizes = true;
      ControlLoop c(m, o, loop(mode, 0.01), [&](double, const VecX& q, const VecX& v, VecX& tau) {
        sizes = sizes && q.size() == 4 && v.size() == 3 && std::abs(q.norm() - 1) < 1e-12;
        tau = -0.2 * v;
      });
      c.reset(0, q0, v0);
      Motion& motion = c.integrator().motion();
      const double E0 = motion.energy_at(c.integrator().y().data()).total();
      for (int k = 0; k < 200; ++k) REQUIRE(c.step().ok);
      const double E = motion.energy_at(c.integrator().y().data()).total(),
                   W = c.integrator().work();
      INFO("E − E0 = " << E - E0 << " J, W = " << W << " J");
      CHECK(sizes);
      CHECK(W < -0.5);  // the controller dissipated
      CHECK(std::abs(E - E0 - W) < (o.kind == IntegratorKind::Rk4 ? 1e-9 : 1e-7) * std::abs(E0));
    }
  }
}

TEST_CASE("a controller whose sampled loop grows is named as the cause of the failure",
          "[control][divergence]") {
  // The pendulum (I = 1, ω₀² = 9.81) under τ = −4e6 θ − 1e3 θ̇ held over 1 ms: ρ(Φ + Γ K) =
  // √2 (python/tests/test_control.py checks the number against scipy); rk4's 20 substeps follow
  // the model itself.
  const Model m = load_model(model_path("pendulum.json"));
  ControlLoop c(m, fixed(IntegratorKind::Rk4, 5e-5), loop(ControlMode::ZeroOrderHold, 1e-3),
                pd(VecX::Constant(1, 4e6), VecX::Constant(1, 1e3), VecX::Zero(1)));
  c.reset(0, VecX::Constant(1, 0.1), VecX::Zero(1));
  const Status st = c.run(2.0);
  REQUIRE(!st.ok);
  CHECK_THAT(st.message, Catch::Contains("the controller is the likely cause") &&
                             Catch::Contains("grow ×1.41 a period"));
  // A gentle PD law runs.
  ControlLoop g(m, fixed(IntegratorKind::Rk4, 1e-3), loop(ControlMode::ZeroOrderHold, 1e-3),
                pd(VecX::Constant(1, 100), VecX::Constant(1, 20), VecX::Zero(1)));
  g.reset(0, VecX::Constant(1, 0.1), VecX::Zero(1));
  CHECK(g.run(1.0).ok);
}

TEST_CASE("a stiff PD law inside f is called diverged only beyond rk4's limit on its loop",
          "[control][divergence]") {
  // track's computed torque on the finger, ë + K_d ė + K_p e = 0 critically damped at ω =
  // √K_p: a double eigenvalue −ω, rk4 stable for ω dt ≤ 2.785. At ω dt = 2.5 (1 ms) it tracks
  // to 1e-5 rad, though the controller's work inside the steps leaves W's quadrature far from
  // E (W = −2e-4 J, E = 3e-5 J: the energy watch alone called it diverged at t = 2 ms); at
  // ω dt = 3 it diverges, and the controller is named.
  const std::string track =
      "track " + model_path("finger.json") + " --to 0.3,0.5,0.4,0.3 --control evaluation";
  const Run inside = run(track + " --kp 6.25e6 --kd 5000 --json");
  INFO(inside.out);
  REQUIRE(inside.code == 0);
  CHECK(nlohmann::json::parse(inside.out)["max_tracking_error"].get<double>() < 1e-4);
  const Run beyond = run(track + " --kp 9e6 --kd 6000");
  INFO(beyond.out);
  CHECK(beyond.code == 1);
  CHECK_THAT(beyond.out, Catch::Contains("the solution diverges") &&
                             Catch::Contains("the controller is the likely cause"));
}
