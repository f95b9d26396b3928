// Prescribed coordinates (driven joints, core/model/prescribed_motion.hpp, sim/motion.cpp): the
// simulator holds the coordinate on its motion by the joint torque that gives its q̈ exactly,
// whose work enters the energy balance; the torque is inverse dynamics' at the prescribed
// motion; the JSON key is checked with its path.
#include <catch2/catch.hpp>
#include <cmath>

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "sim/integrator.hpp"
#include "sim/motion.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A revolute hub about z driving a pendulum arm on a second revolute joint (free), under gravity
// tilted so that the arm swings; the hub follows `motion` (JSON).
std::string driven(const std::string& motion) {
  return R"({"name": "driven", "gravity": [0, -3, -9.81], "bodies": [
    {"name": "hub", "parent": "world", "joint": {"name": "hub", "type": "revolute",
     "axis": [0, 0, 1], "prescribed": )" +
         motion + R"(},
     "elements": [{"type": "rigid_body", "mass": 2, "com": [0.1, 0, 0],
                   "inertia": {"ixx": 0.02, "iyy": 0.03, "izz": 0.04}}]},
    {"name": "arm", "parent": "hub", "joint": {"name": "swing", "type": "revolute",
     "axis": [0, 1, 0], "origin": {"xyz": [0.3, 0, 0]}},
     "elements": [{"type": "lumped_point", "node": [0.4, 0, 0], "mass": 1}]}]})";
}

VecX v2(double a, double b) { return (VecX(2) << a, b).finished(); }

}  // namespace

TEST_CASE("a prescribed coordinate follows its motion, its drive counted as work", "[prescribed]") {
  const Model m = load_text(driven(R"({"polynomial": [0, 0.5, -0.3, 0.1]})"));
  REQUIRE(m.prescribed.size() == 1);
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-11;
  o.adaptive.atol = 1e-13;
  auto run = make_integrator(m, o);
  run->reset(0, v2(0, 0.2), v2(0.5, 0));  // (the hub's q(0) = 0, q̇(0) = 0.5: on its motion)
  Workspace ws(m);
  double worst = 0;
  for (int k = 1; k <= 20; ++k) {
    const double t = 0.1 * k;
    REQUIRE(run->advance_to(t).ok);
    const auto [q, v, a] = m.prescribed[0].motion.at(t);
    worst = std::max({worst, std::abs(run->q()[0] - q), std::abs(run->qd()[0] - v)});
  }
  CHECK(worst < 1e-8);  // the integrator's tolerance; the pull-back at 10/s holds the drift
  // The energy balance E(t) − E(0) = W(t) holds with the driving torque's work in W.
  const double E0 = energy(m, ws, v2(0, 0.2), v2(0.5, 0)).total();
  const double E1 = energy(m, ws, run->q(), run->qd()).total();
  CHECK(std::abs(E1 - E0 - run->work()) < 1e-8 * (std::abs(E0) + std::abs(run->work())));
  CHECK(std::abs(run->work()) > 1e-2);  // (the drive does work: the check above means something)
}

TEST_CASE("the driving torque is the inverse dynamics torque of the prescribed motion",
          "[prescribed]") {
  // At one state on the motion, the simulator's q̈ has the prescribed q̈ on the hub, and the free
  // swing's q̈ is what inverse dynamics needs with τ on the hub only.
  const Model m = load_text(driven(R"({"spin_up": {"rate": 4, "time": 15}})"));
  const double t = 3;
  const auto [q, v, a] = m.prescribed[0].motion.at(t);
  Motion motion(m);
  const double y[5] = {q, 0.3, v, -0.2, 0};  // (q, v, W) of a flat model
  double ydot[5];
  REQUIRE(motion.rhs(t, y, ydot).ok);
  const VecX qdd = v2(ydot[2], ydot[3]);
  CHECK(std::abs(qdd[0] - a) < 1e-12 * (1 + std::abs(a)));
  Workspace ws(m);
  inverse_dynamics(m, ws, v2(q, 0.3), v2(v, -0.2), qdd);
  CHECK(std::abs(ws.tau[1]) < 1e-10);  // no torque on the free joint: it moved by itself
}

TEST_CASE("a bad prescribed motion is refused naming the key", "[prescribed]") {
  CHECK_THAT(text_error(driven(R"({"polynomial": []})")),
             Catch::Contains("/bodies/0/joint/prescribed/polynomial: expected 1 to 16"));
  CHECK_THAT(text_error(driven(R"({"spin_up": {"rate": 4}})")),
             Catch::Contains("/bodies/0/joint/prescribed/spin_up/time"));
  CHECK_THAT(text_error(driven(R"({"sine": 1})")),
             Catch::Contains("/bodies/0/joint/prescribed/sine: unknown key"));
  CHECK_THAT(text_error(R"({"name": "x", "bodies": [{"name": "b", "parent": "world",
      "joint": {"type": "spherical", "prescribed": {"polynomial": [0]}},
      "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 1, "iyy": 1,
      "izz": 1}}]}]})"),
             Catch::Contains("/bodies/0/joint/prescribed: only a joint of one rate"));
}

TEST_CASE("the driven motion's Jacobian (bdf's) equals differences of the driven q̈",
          "[prescribed]") {
  // ∂q̈/∂(q, v) of f with the driving torque τ_P(q, v) inside it, against central differences of
  // Motion::rhs; and differs from the undriven Jacobian at the same τ (the check means something).
  const Model m = load_text(driven(R"({"spin_up": {"rate": 3, "time": 2}})"));
  Motion motion(m);
  DerivativeWorkspace d(m);
  Workspace ws(m);
  const int n = m.n();
  VecX y(2 * n + 1), f(2 * n + 1), fp(2 * n + 1), fm(2 * n + 1);
  y << 0.4, -0.7, 1.1, 0.3, 0;  // off the motion: the pull-back acts too
  const double t = 0.8;
  REQUIRE(motion.rhs(t, y.data(), f.data()).ok);
  const VecX tau = motion.applied_actuation();
  REQUIRE(forward_dynamics_derivatives(m, ws, d, y.head(n), y.segment(n, n), tau).ok);
  MatX Jq = d.dqdd_dq, Jv = d.dqdd_dv;
  const MatX undriven_q = Jq;
  motion.drive_jacobian(d.Minv, Jq, Jv);
  MatX Dq(n, n), Dv(n, n);
  const double h = 1e-6;
  for (int j = 0; j < 2 * n; ++j) {
    VecX yp = y, ym = y;
    yp[j] += h;
    ym[j] -= h;
    REQUIRE(motion.rhs(t, yp.data(), fp.data()).ok);
    REQUIRE(motion.rhs(t, ym.data(), fm.data()).ok);
    (j < n ? Dq.col(j) : Dv.col(j - n)) = (fp - fm).segment(n, n) / (2 * h);
  }
  CHECK(max_abs(Jq - Dq) < 1e-7 * (1 + max_abs(Dq)));
  CHECK(max_abs(Jv - Dv) < 1e-7 * (1 + max_abs(Dv)));
  CHECK(max_abs(undriven_q - Dq) > 1.0);
  // The hub's row is the pull-back's alone: q̈_hub = q̈(t) + 2ω (q̇(t) − q̇) + ω² (q(t) − q).
  CHECK(Jq(0, 0) == Approx(-kPrescribedRate * kPrescribedRate).epsilon(1e-9));
  CHECK(Jv(0, 0) == Approx(-2 * kPrescribedRate).epsilon(1e-9));
}
