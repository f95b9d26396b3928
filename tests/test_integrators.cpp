// The integrators of sim/integrator.hpp against independent references: convergence orders
// measured against a much tighter run, the energy balance E(t) − E(0) = W(t), bounded energy
// error of the symplectic method, a stiff spring against its closed form, failures reported.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/derivatives/derivatives.hpp"
#include "core/kinematics/sampling.hpp"
#include "sim/integrator.hpp"
#include "sim/sundials_integrators.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// (q, q̇) at t = T/20, 2T/20, …, T from (q0, q̇0), by the integrator of `o`.
std::vector<VecX> samples(const Model& m, const IntegratorOptions& o, const VecX& q0,
                          const VecX& qd0, double T) {
  auto integ = make_integrator(m, o);
  integ->reset(0, q0, qd0, T);
  std::vector<VecX> out;
  for (int i = 1; i <= 20; ++i) {
    const Status st = integ->advance_to(T * i / 20);
    REQUIRE(st.ok);
    out.push_back(integ->y().head(2 * m.n()));
  }
  return out;
}

// The state error along the trajectory: max over the samples of ‖x − x_ref‖∞.
double max_error(const std::vector<VecX>& x, const std::vector<VecX>& ref) {
  double e = 0;
  for (std::size_t i = 0; i < ref.size(); ++i)
    e = std::max(e, (x[i] - ref[i]).cwiseAbs().maxCoeff());
  return e;
}

IntegratorOptions fixed(IntegratorKind kind, double dt) {
  return {.kind = kind, .fixed = {.dt = dt}};
}

IntegratorOptions adaptive(IntegratorKind kind, double rtol, double atol) {
  return {.kind = kind, .adaptive = {.rtol = rtol, .atol = atol}};
}

// A 1 kg point mass on a 1 m arm about y with a joint spring k: ω = √k rad/s, no gravity.
struct Case {
  Model m;
  VecX q0, qd0;
};

Case double_pendulum() {  // nonlinear, full inertia tensors, skew axes
  Case c{load_model(model_path("spatial_double_pendulum.json")), VecX(2), VecX(2)};
  c.q0 << 0.7, -1.2;
  c.qd0 << 1.5, -2.0;
  return c;
}

}  // namespace

TEST_CASE("options checks name the bad field", "[integrators]") {
  CHECK(FixedStepOptions{.dt = -1}.check().rfind("dt:", 0) == 0);
  CHECK(FixedStepOptions{.dt = 1e-3}.check().empty());
  CHECK(AdaptiveOptions{.rtol = 0}.check().rfind("rtol:", 0) == 0);
  CHECK(AdaptiveOptions{.rtol = 1e-17}.check().rfind("rtol:", 0) == 0);
  CHECK(AdaptiveOptions{.atol = -1}.check().rfind("atol:", 0) == 0);
  CHECK(AdaptiveOptions{.h_max = NAN}.check().rfind("h_max:", 0) == 0);
  CHECK(AdaptiveOptions{}.check().empty());
  const Model m = load_model(model_path("pendulum.json"));
  CHECK_THROWS_WITH(make_integrator(m, fixed(IntegratorKind::Rk4, 0)),
                    Catch::StartsWith("dt: the step must be a positive number"));
}

TEST_CASE("convergence orders on a spatial double pendulum", "[integrators]") {
  const Case c = double_pendulum();
  const double T = 1.0;
  // Reference: Dormand–Prince at rtol 1e-13, checked against RK4 at 1e-4 s (agree to 1e-10).
  const auto ref = samples(c.m, adaptive(IntegratorKind::Dopri, 1e-13, 1e-15), c.q0, c.qd0, T);
  REQUIRE(max_error(samples(c.m, fixed(IntegratorKind::Rk4, 1e-4), c.q0, c.qd0, T), ref) < 1e-10);
  const auto error = [&](const IntegratorOptions& o) {
    return max_error(samples(c.m, o, c.q0, c.qd0, T), ref);
  };

  SECTION("RK4: order 4 ± 0.3") {
    for (double dt : {1.0 / 400, 1.0 / 800}) {  // asymptotic (5th-order-like above 1/200)
      const double e1 = error(fixed(IntegratorKind::Rk4, dt)),
                   e2 = error(fixed(IntegratorKind::Rk4, dt / 2));
      INFO("dt " << dt << ": " << e1 << " -> " << e2);
      CHECK(std::log2(e1 / e2) == Approx(4).margin(0.3));
    }
  }
  SECTION("symplectic Euler: order 1 ± 0.2") {
    for (double dt : {1.0 / 2000, 1.0 / 4000, 1.0 / 8000}) {
      const double e1 = error(fixed(IntegratorKind::Euler, dt)),
                   e2 = error(fixed(IntegratorKind::Euler, dt / 2));
      INFO("dt " << dt << ": " << e1 << " -> " << e2);
      CHECK(std::log2(e1 / e2) == Approx(1).margin(0.2));
    }
  }
  SECTION("Dormand–Prince: error proportional to the tolerance within 10x over 4 decades") {
    double lo = INFINITY, hi = 0;
    for (double tol : {1e-5, 1e-6, 1e-7, 1e-8, 1e-9}) {
      const double e = error(adaptive(IntegratorKind::Dopri, tol, tol));
      INFO("dopri tol " << tol << ": error " << e);
      INFO("tol " << tol << ": error " << e);
      lo = std::min(lo, e / tol);
      hi = std::max(hi, e / tol);
    }
    INFO("error / tol in [" << lo << ", " << hi << "]");
    CHECK(hi / lo <= 10);
    CHECK(hi <= 1000);  // the global error stays within ~10² of the local tolerance
  }
  SECTION("Dormand–Prince landing on the outputs: no interpolation error") {
    for (double tol : {1e-6, 1e-8, 1e-10}) {
      IntegratorOptions o = adaptive(IntegratorKind::Dopri, tol, tol);
      const double dense = error(o);
      o.adaptive.stop_at_outputs = true;
      const double landed = error(o);
      INFO("tol " << tol << ": dense output " << dense << ", landing " << landed);
      CHECK(landed < dense);
      CHECK(landed < 100 * tol);
    }
  }
  SECTION("BDF converges") {
    double last = INFINITY;
    for (double tol : {1e-4, 1e-6, 1e-8, 1e-10}) {
      const double e = error(adaptive(IntegratorKind::Bdf, tol, tol));
      INFO("bdf tol " << tol << ": error " << e);
      INFO("tol " << tol << ": error " << e);
      CHECK(e < last);
      last = e;
    }
    CHECK(last < 1e-5);
  }
}

TEST_CASE("energy: conservative finger, symplectic Euler over 1e5 steps, damped and driven balance",
          "[integrators]") {
  SECTION("the conservative finger keeps its energy to within the tolerance") {
    const Model m = load_model(model_path("finger.json"));
    VecX q0(4), qd0(4);
    q0 << 0.1, 0.5, 0.6, 0.5;
    qd0 << 0.5, 1, 1, 1;
    for (IntegratorKind k : {IntegratorKind::Dopri, IntegratorKind::Bdf}) {
      const double tol = 1e-9;
      auto integ = make_integrator(m, adaptive(k, tol, tol));
      integ->reset(0, q0, qd0, 2.0);
      const double E0 = integ->motion().energy_at(integ->y().data()).total();
      double drift = 0, scale = 0;
      for (int i = 1; i <= 100; ++i) {
        REQUIRE(integ->advance_to(0.02 * i).ok);
        const Energy E = integ->motion().energy_at(integ->y().data());
        drift = std::max(drift, std::abs(E.total() - E0));
        scale = std::max(scale, E.kinetic);
        CHECK(integ->work() == 0);  // nothing non-conservative acts
      }
      INFO(integrator_name(k) << ": drift " << drift << " J, kinetic scale " << scale << " J");
      INFO(integrator_name(k) << ": drift " << drift << " J, kinetic scale " << scale << " J");
      // Relative to the tolerance: Dormand–Prince within 10 tol; BDF, whose global error runs
      // 10–100x its local tolerance on oscillatory motion (docs/simulation.md), within 100 tol.
      CHECK(drift <= (k == IntegratorKind::Bdf ? 100 : 10) * tol * scale);
    }
  }
  SECTION("symplectic Euler: bounded energy error, no drift, over 1e5 steps of a pendulum") {
    const Model m = load_model(model_path("pendulum.json"));
    auto integ = make_integrator(m, fixed(IntegratorKind::Euler, 1e-2));
    integ->reset(0, VecX::Constant(1, 1.0), VecX::Zero(1));
    const double E0 = integ->motion().energy_at(integ->y().data()).total();
    double early = 0, late = 0;
    for (int k = 1; k <= 100000; ++k) {
      REQUIRE(integ->step().ok);
      if (k % 10) continue;
      const double e = std::abs(integ->motion().energy_at(integ->y().data()).total() - E0);
      (k <= 10000 ? early : late) = std::max(k <= 10000 ? early : late, e);
    }
    INFO("max |E - E0| over the first 1e4 steps " << early << " J, over the rest " << late);
    CHECK(late <= 1.5 * early);                    // bounded: no secular growth
    CHECK(early <= 0.1 * std::abs(E0 - (-9.81)));  // O(dt) of the swing energy 9.81(1 - cos 1)
    // RK4 at the same step drifts (dissipates) secularly: the contrast the test is about.
    auto rk4 = make_integrator(m, fixed(IntegratorKind::Rk4, 1e-2));
    rk4->reset(0, VecX::Constant(1, 1.0), VecX::Zero(1));
    REQUIRE(rk4->advance_to(1000).ok);
    const double rk4_drift = std::abs(rk4->motion().energy_at(rk4->y().data()).total() - E0);
    INFO("RK4 after 1e5 steps: " << rk4_drift);
    CHECK(rk4_drift > 0);
  }
  SECTION("semi-implicit Euler with a configuration-dependent M^s is not symplectic: it drifts") {
    // The finger (M^s depends on the flexion angles), conservative: the energy error over the
    // last tenth of 400 s is many times that of the first tenth, where the pendulum's (above)
    // does not grow; by 520 s the run diverges. docs/simulation.md says so.
    const Model m = load_model(model_path("finger.json"));
    VecX q0(4), qd0(4);
    q0 << 0.1, 0.5, 0.6, 0.5;
    qd0 << 0.5, 1, 1, 1;
    auto integ = make_integrator(m, fixed(IntegratorKind::Euler, 1e-3));
    integ->reset(0, q0, qd0);
    const double E0 = integ->motion().energy_at(integ->y().data()).total();
    double early = 0, late = 0;
    for (int i = 1; i <= 400; ++i) {
      REQUIRE(integ->advance_to(1.0 * i).ok);
      const double e = std::abs(integ->motion().energy_at(integ->y().data()).total() - E0);
      if (i <= 40) early = std::max(early, e);
      if (i > 360) late = std::max(late, e);
    }
    INFO("max |E - E0| over the first 40 s " << early << " J, over the last 40 s " << late);
    CHECK(late > 10 * early);
  }
  SECTION("damped and driven: E(t) − E(0) = W(t) to within the tolerance") {
    const Model m = load_model(model_path("branched_tree.json"));  // springs, dampers, slider
    const int n = m.n();
    const Actuation tau = [n](double t, VecX& u) {
      for (int i = 0; i < n; ++i) u[i] = 0.3 * std::sin(3 * t + i);
    };
    for (IntegratorKind k : {IntegratorKind::Dopri, IntegratorKind::Bdf}) {
      const double tol = 1e-9;
      auto integ = make_integrator(m, adaptive(k, tol, tol), tau);
      integ->reset(0, VecX::Constant(n, 0.2), VecX::Constant(n, -0.5), 1.0);
      const double E0 = integ->motion().energy_at(integ->y().data()).total();
      double balance = 0, scale = 0, work = 0;
      for (int i = 1; i <= 50; ++i) {
        REQUIRE(integ->advance_to(0.02 * i).ok);
        const Energy E = integ->motion().energy_at(integ->y().data());
        balance = std::max(balance, std::abs(E.total() - E0 - integ->work()));
        scale = std::max({scale, E.kinetic, std::abs(E.total())});
        work = std::max(work, std::abs(integ->work()));
      }
      INFO(integrator_name(k) << ": balance " << balance << " J, |W| up to " << work << " J, scale "
                              << scale << " J");
      CHECK(work > 1e-3 * scale);  // the forces did real work
      INFO(integrator_name(k) << ": balance " << balance << " scale " << scale);
      CHECK(balance <= (k == IntegratorKind::Bdf ? 100 : 10) * tol * scale);
    }
  }
}

TEST_CASE("a 1e4 rad/s joint spring: RK4 at 1e-3 s fails cleanly, BDF follows the closed form",
          "[integrators]") {
  const Model m = load_text(arm_json(1e8));  // ω = 1e4 rad/s
  const VecX q0 = VecX::Constant(1, 0.1), qd0 = VecX::Zero(1);
  auto rk4 = make_integrator(m, fixed(IntegratorKind::Rk4, 1e-3));
  rk4->reset(0, q0, qd0);
  const Status st = rk4->advance_to(1.0);
  REQUIRE_FALSE(st.ok);
  INFO(st.message);
  CHECK_THAT(st.message, Catch::Contains("the solution diverges") &&
                             Catch::Contains("beyond the stability limit") &&
                             Catch::Contains("1e+04 rad/s") && Catch::StartsWith("at t = "));
  CHECK(st.diverged);
  CHECK(rk4->y().allFinite());  // the last good state is kept, never a NaN
  CHECK(rk4->t() < 1.0);

  // θ(t) = θ0 cos ωt.
  auto bdf = make_integrator(m, adaptive(IntegratorKind::Bdf, 1e-10, 1e-12));
  bdf->reset(0, q0, qd0);
  double err = 0;
  for (int i = 1; i <= 40; ++i) {
    const double t = 2.5e-4 * i;  // 10 ms, 16 periods
    REQUIRE(bdf->advance_to(t).ok);
    err = std::max(err, std::abs(bdf->q()[0] - 0.1 * std::cos(1e4 * t)));
  }
  INFO("BDF max error " << err << " rad; " << bdf->stats().steps << " steps");
  CHECK(err < 1e-5);

  // Stiff and damped (ζ = 5): BDF takes steps far beyond RK4's stability limit 2.8/ω.
  const Model damped = load_text(arm_json(1e8, 1e5));
  auto stiff = make_integrator(damped, adaptive(IntegratorKind::Bdf, 1e-6, 1e-9));
  stiff->reset(0, q0, qd0);
  REQUIRE(stiff->advance_to(1.0).ok);
  // Overdamped: θ ≈ θ0 e^{−t ω²/(2ζω)} decays to nothing after 1 s; few steps needed.
  CHECK(std::abs(stiff->q()[0]) < 1e-6);
  // RK4 would need about 36000: its fast mode λ ≈ −2ζω = −1e5 /s limits it to h ≤ 2.79/|λ|.
  CHECK(stiff->stats().steps < 2000);
  CHECK(stiff->stats().jac_evals > 0);
}

TEST_CASE("a singular M^s stops the run with the time and the coordinate", "[integrators]") {
  // A slider on a turntable, its mass 0.5 m out on the slider: M^s = diag(m r², m) with
  // r = 0.5 + reach, singular at reach = −0.5 (regular at the states compile samples).
  const Model m = load_text(R"({"name": "turntable", "gravity": [0, 0, -9.81], "bodies": [
    {"name": "table", "parent": "world", "joint": {"name": "spin", "type": "revolute",
     "axis": [0, 0, 1]}, "elements": []},
    {"name": "slider", "parent": "table", "joint": {"name": "reach", "type": "prismatic",
     "axis": [1, 0, 0]}, "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1.0}]}]})");
  for (IntegratorKind k : {IntegratorKind::Rk4, IntegratorKind::Dopri, IntegratorKind::Bdf}) {
    IntegratorOptions o{.kind = k};
    auto integ = make_integrator(m, o);
    integ->reset(0, Eigen::Vector2d(0, -0.5), VecX::Ones(2));
    const Status st = integ->advance_to(0.1);
    INFO(integrator_name(k) << ": " << st.message);
    CHECK_FALSE(st.ok);
    CHECK_THAT(st.message, Catch::StartsWith("at t = 0 s: ") && Catch::Contains("'spin'") &&
                               Catch::Contains("singular"));
    CHECK(integ->t() == 0);
  }
}

namespace {

// The analytic BDF Jacobian against central differences of the integrator's own right-hand side
// at its current y (the same chart centre), step 1e-5 max(1, |y_i|) (at 1e-6 the round-off of the
// light fingers' large q̈ shows); returns max |J_a − J_c| over the rows of (ξ̇, v̇) relative to the
// largest entry of each row block. (The integrator's own difference Jacobian is one-sided, accurate
// only to about 1e-4 here: the space robot's light fingers make q̈ strongly curved.)
double jacobian_mismatch(Bdf& bdf, double t) {
  const int n = bdf.motion().n(), N = 2 * n + 1;
  VecX y = bdf.y(), fp(N), fm(N);
  MatX Ja(N, N), Jc(N, N);
  REQUIRE(bdf.analytic_jacobian(t, y.data(), Ja.data()) == 0);
  for (int j = 0; j < 2 * n; ++j) {
    const double y0 = y[j], h = 1e-5 * std::max(1.0, std::abs(y0));
    y[j] = y0 + h;
    REQUIRE(bdf.rhs(t, y.data(), fp.data()) == 0);
    y[j] = y0 - h;
    REQUIRE(bdf.rhs(t, y.data(), fm.data()) == 0);
    y[j] = y0;
    Jc.col(j) = (fp - fm) / (2 * h);
  }
  double worst = 0;
  for (int rows : {0, n}) {
    const MatX a = Ja.block(rows, 0, n, 2 * n), c = Jc.block(rows, 0, n, 2 * n);
    worst = std::max(worst, (a - c).cwiseAbs().maxCoeff() / std::max(1.0, a.cwiseAbs().maxCoeff()));
  }
  return worst;
}

}  // namespace

TEST_CASE("bdf: the analytic Jacobian equals the difference Jacobian in the chart",
          "[integrators][derivatives]") {
  // The space robot's free base (chart coordinates ξ, away from ξ = 0 after some steps), the
  // finger (flat, gravity, springs), the four-bar finger (a coupling law), the flyball
  // governor (two-point spring-dampers), and closed loops (the constrained q̈ at the run's
  // Baumgarte rate: the five-bar, and the four-bar finger closed by a constraint).
  for (const char* name :
       {"space_robot.json", "finger.json", "finger_fourbar.json", "iftomm_a05_flyball.json",
        "five_bar.json", "finger_fourbar_loop.json"}) {
    INFO(name);
    const Model m = load_model(model_path(name));
    auto integ = make_integrator(m, adaptive(IntegratorKind::Bdf, 1e-8, 1e-10));
    auto& bdf = dynamic_cast<Bdf&>(*integ);
    const VecX q0 = neutral_posture(m), qd0 = VecX::LinSpaced(m.n(), 0.3, -0.4);
    integ->reset(0, q0, qd0, 1);
    REQUIRE(bdf.analytic());
    CHECK(jacobian_mismatch(bdf, 0) < 1e-6);
    REQUIRE(integ->advance_to(0.3).ok);
    if (!bdf.motion().flat()) CHECK(bdf.motion().chart_extent(bdf.y().data()) > 0.05);
    CHECK(jacobian_mismatch(bdf, 0.3) < 1e-6);
  }
}

TEST_CASE("bdf: a model the derivatives refuse, or a controller, falls back to differences",
          "[integrators][derivatives]") {
  const Model paper = load_model(model_path("finger_paper.json"));  // an explicit table
  REQUIRE_FALSE(derivatives_unsupported(paper).empty());
  auto a = make_integrator(paper, adaptive(IntegratorKind::Bdf, 1e-6, 1e-8));
  a->reset(0, neutral_posture(paper), VecX::Zero(paper.n()), 1);
  CHECK_FALSE(dynamic_cast<Bdf&>(*a).analytic());
  const Model finger = load_model(model_path("finger.json"));
  auto b = make_integrator(finger, adaptive(IntegratorKind::Bdf, 1e-6, 1e-8));
  b->set_control([](double, const VecX&, const VecX& v, VecX& tau) { tau = -v; });
  b->reset(0, neutral_posture(finger), VecX::Zero(finger.n()), 1);
  CHECK_FALSE(dynamic_cast<Bdf&>(*b).analytic());
}

TEST_CASE("bdf: orders 1-2 step over a flexible bar's undamped modes, orders 3-5 are held",
          "[integrators]") {
  // The spin-up beam (8 parts, 0–4 s of the spin-up): its undamped modes spread from 3.8 to
  // about 1e4 rad/s, loaded slowly and barely excited. BDF1–2 are A-stable, so their step
  // follows the slow motion. BDF3–5 are unstable on a bounded region that crosses into the left
  // half-plane about the imaginary axis (A(α)-stable, α = 86°, 73°, 52°): with modes at every
  // frequency, some ω h falls in it at any step longer than about 1/ω_max, and the round-off in
  // that mode grows until the step is cut there.
  const Model m = load_text(R"({"name": "spin-up", "gravity": [0, 0, 0], "bodies": [
    {"name": "hub", "parent": "world", "joint": {"name": "hub", "type": "revolute",
     "axis": [0, 0, 1], "prescribed": {"spin_up": {"rate": 4, "time": 15}}},
     "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 0.1, "iyy": 0.1, "izz": 0.1}}]}],
    "flexible_bars": [{"name": "beam", "parent": "hub", "length": 10, "segments": 8,
     "torsion": false, "section": {"EA": 2.8e7, "EIy": 1.4e4, "EIz": 1.4e4, "rhoA": 1.2}}]})");
  long steps[2] = {0, 0};
  VecX q[2];
  for (int k : {0, 1}) {
    IntegratorOptions o = adaptive(IntegratorKind::Bdf, 1e-7, 1e-9);
    o.adaptive.max_order = k == 0 ? 2 : 5;
    auto bdf = make_integrator(m, o);
    bdf->reset(0, VecX::Zero(m.n()), VecX::Zero(m.n()));
    REQUIRE(bdf->advance_to(4.0).ok);
    steps[k] = bdf->stats().steps;
    q[k] = bdf->q();
  }
  INFO("steps: order 2 " << steps[0] << ", order 5 " << steps[1] << "; max |q2 - q5| "
                         << max_abs(q[0] - q[1]));
  CHECK(steps[1] > 10 * steps[0]);  // measured 35x
  CHECK(max_abs(q[0] - q[1]) < 1e-5);
  CHECK(IntegratorOptions{.kind = IntegratorKind::Bdf, .adaptive = {.max_order = 6}}.check().rfind(
            "max_order:", 0) == 0);
}
