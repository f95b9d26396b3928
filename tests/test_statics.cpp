// Statics (sim/statics.hpp, `femdyn statics`): the rest configuration under springs, gravity
// and loads, against closed forms and the published large-deflection benchmarks: a sprung arm
// under gravity, Gerstmayr & Irschik's cantilever under a large tip force, Simo & Vu-Quoc's
// roll-up under a tip moment, Bathe & Bolourchi's 45° bend under a load out of its plane. And
// the refusals: closed loops, no equilibrium.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/loops/constraint_kinematics.hpp"
#include "core/model/names.hpp"
#include "sim/statics.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string statics_number(double x) { return format_number(x, "%.17g"); }

// The world position of body `name`'s origin at q.
Vec3 origin_of(const MechanismSpec& spec, const VecX& q, const std::string& name) {
  const Model m = compile(spec);
  Workspace ws(m);
  const VecX z = VecX::Zero(m.n());
  inverse_dynamics(m, ws, q, z, z);
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].name == name) return ws.origin + ws.body[b].p;
  FAIL("no body " << name);
  return Vec3::Zero();
}

StaticsResult solved(const MechanismSpec& spec, const StaticsOptions& o = {}) {
  StaticsResult r = solve_statics(spec, o);
  INFO(r.status.message);
  REQUIRE(r.status.ok);
  CHECK(r.lambda == 1);
  CHECK(r.residual <= 1e-10 * r.scale);
  return r;
}

LoadSpec tip_load(const std::string& body, const Vec3& force, const Vec3& torque = Vec3::Zero()) {
  LoadSpec l;
  l.body = body, l.force = force, l.torque = torque, l.where = "test load";
  return l;
}

// Gerstmayr & Irschik's cantilever (J. Sound Vib. 318, 2008; Exudyn's test suite): L = 2 m,
// E = 2.07e11 Pa, 0.1 m square, tip force 3EI/L² transverse, fixed in direction.
std::string gerstmayr(int n) {
  return R"({"name": "Gerstmayr-Irschik", "bodies": [], "flexible_bars": [{"name": "beam",
    "parent": "world", "length": 2, "segments": )" +
         std::to_string(n) + R"(, "torsion": false, "section": {"E": 2.07e11,
    "density": 7800, "area": 0.01, "Iy": 8.333333333333333e-6, "Iz": 8.333333333333333e-6}}]})";
}

}  // namespace

TEST_CASE("statics: a sprung arm rests where k θ = m g l cos θ", "[statics]") {
  // arm_json: 1 kg at 1 m on a joint about y with a spring k, gravity g; θ > 0 turns it down.
  for (const double k : {2.0, 20.0, 200.0}) {
    const double g = 9.81;
    double lo = 0, hi = std::numbers::pi / 2;  // k θ − g cos θ rises from −g to k π/2
    for (int i = 0; i < 200; ++i)
      ((k * (lo + hi) / 2 - g * std::cos((lo + hi) / 2) < 0) ? lo : hi) = (lo + hi) / 2;
    const StaticsResult r = solved(parse_spec(arm_json(k, 0, g), "arm"));
    INFO("k = " << k);
    CHECK(std::abs(r.q[0] - lo) < 1e-10);
  }
}

TEST_CASE("statics: Gerstmayr and Irschik's cantilever converges at order 2", "[statics]") {
  // Converged tip displacement (x, y) = (−0.508537304326, −1.207239854550) m.
  const Vec3 reference(2 - 0.508537304326, -1.207239854550, 0);
  std::vector<double> errors;
  for (int n : {8, 16, 32}) {
    const MechanismSpec spec = parse_spec(gerstmayr(n), "gerstmayr");
    StaticsOptions o;
    o.loads = {tip_load("beam.tip", Vec3(0, -3 * 2.07e11 * 8.333333333333333e-6 / 4, 0))};
    const StaticsResult r = solved(spec, o);
    errors.push_back((origin_of(spec, r.q, "beam.tip") - reference).norm());
  }
  // measured: 6.4e-3, 1.6e-3, 3.9e-4 m
  CHECK(errors[2] < 5e-4);
  CHECK(std::log2(errors[0] / errors[1]) > 1.9);
  CHECK(std::log2(errors[1] / errors[2]) > 1.9);
}

TEST_CASE("statics: a tip moment 2π EI/L rolls the cantilever into a circle", "[statics]") {
  // Simo & Vu-Quoc (1986): L = 10, EI = 86.9e3; the tip returns to the clamp. With the
  // moment at the tip each of the n joints turns by 2π/n, and the pieces close a polygon.
  for (int n : {8, 13}) {
    const MechanismSpec spec = parse_spec(R"({"name": "roll-up", "bodies": [],
      "flexible_bars": [{"name": "beam", "parent": "world", "length": 10, "segments": )" +
                                              std::to_string(n) + R"(, "torsion": false,
        "section": {"EA": 1e9, "EIy": 86900, "EIz": 86900, "rhoA": 1}}]})",
                                          "roll-up");
    StaticsOptions o;
    o.loads = {tip_load("beam.tip", Vec3::Zero(), Vec3(0, 0, 2 * std::numbers::pi * 8690))};
    const StaticsResult r = solved(spec, o);
    INFO("n = " << n);
    CHECK(origin_of(spec, r.q, "beam.tip").norm() < 1e-9);
  }
}

TEST_CASE("statics: Bathe and Bolourchi's 45-degree bend under a load out of its plane",
          "[statics]") {
  // R = 100 in, 1 × 1 in, E = 1e7 psi, ν = 0 (G = E/2), J = 0.1406 in⁴ (the square's), a 600 lb
  // tip load normal to the bend's plane. The arc is K chords, each a bar of one segment clamped
  // to the previous one's tip turned by 45°/K. Published tip displacement: 53.4 in along the
  // load (later converged solutions 53.58), (−23.5, −13.4) in the plane.
  const int K = 32;
  const double R = 100, dphi = std::numbers::pi / 4 / K, chord = 2 * R * std::sin(dphi / 2);
  std::string bars;
  for (int k = 0; k < K; ++k)
    bars += std::string(k ? ", " : "") + R"({"name": "b)" + std::to_string(k) +
            R"(", "parent": ")" + (k ? "b" + std::to_string(k - 1) + ".tip" : "world") +
            R"(", "length": )" + statics_number(chord) +
            R"(, "segments": 1, "origin": {"rpy": [0, 0, )" + statics_number(k ? dphi : dphi / 2) +
            R"(]}, "section": {"E": 1e7, "G": 5e6, "density": 1,
            "area": 1, "Iy": 0.08333333333333333, "Iz": 0.08333333333333333, "J": 0.1406}})";
  const MechanismSpec spec =
      parse_spec(R"({"name": "bend", "bodies": [], "flexible_bars": [)" + bars + "]}", "bend");
  const std::string tip = "b" + std::to_string(K - 1) + ".tip";
  const Vec3 start = origin_of(spec, VecX::Zero(compile(spec).n_q()), tip);
  CHECK(std::abs(start.x() - R * std::sin(std::numbers::pi / 4)) < 1e-9);
  StaticsOptions o;
  o.loads = {tip_load(tip, Vec3(0, 0, 600))};
  const Vec3 d = origin_of(spec, solved(spec, o).q, tip) - start;
  // measured at K = 32: (−23.72, −13.99, 53.59); at K = 64 (−23.77, −13.86, 53.60)
  CHECK(std::abs(d.z() - 53.58) < 0.05);
  CHECK(std::abs(d.x() - -23.5) < 0.5);
  CHECK(std::abs(d.y() - -13.4) < 0.75);
}

TEST_CASE("statics: Bathe and Bolourchi's bend as one curved bar", "[statics][flexible]") {
  // The same bend as one flexible bar with "curvature" (its joints on the arc, no kink at the
  // clamp). The component along the load converges at order 2 to the later solutions' 53.58
  // (measured 53.397, 53.562, 53.597, 53.604, 53.605 at 8 … 128 parts); the in-plane ones at
  // order 1 (each joint's rotation is a Cardan sequence, whose bending and twist commute only
  // to first order: docs/flexible.md).
  const auto tip = [&](int n) {
    const MechanismSpec spec = parse_spec(R"({"name": "bend", "bodies": [], "flexible_bars": [
      {"name": "b", "parent": "world", "length": )" +
                                              statics_number(100 * std::numbers::pi / 4) +
                                              R"(, "segments": )" + std::to_string(n) + R"(,
       "curvature": {"radius": 100}, "section": {"E": 1e7, "G": 5e6, "density": 1,
       "area": 1, "Iy": 0.08333333333333333, "Iz": 0.08333333333333333, "J": 0.1406}}]})",
                                          "bend");
    StaticsOptions o;
    o.loads = {tip_load("b.tip", Vec3(0, 0, 600))};
    const Vec3 start(100 * std::sin(std::numbers::pi / 4),
                     100 * (1 - std::cos(std::numbers::pi / 4)), 0);
    CHECK((origin_of(spec, VecX::Zero(compile(spec).n_q()), "b.tip") - start).norm() < 1e-12);
    return Vec3(origin_of(spec, solved(spec, o).q, "b.tip") - start);
  };
  const Vec3 d8 = tip(8), d16 = tip(16), d32 = tip(32);
  INFO("d8 " << d8.transpose() << "; d16 " << d16.transpose() << "; d32 " << d32.transpose());
  CHECK(std::abs(d32.z() - 53.58) < 0.05);
  CHECK(std::log2(std::abs(d16.z() - d8.z()) / std::abs(d32.z() - d16.z())) > 1.9);
  CHECK(std::abs(d32.x() - -23.5) < 0.5);
  CHECK(std::abs(d32.y() - -13.4) < 0.75);
}

TEST_CASE("statics: a pendulum started horizontal finds where it hangs", "[statics]") {
  // At θ = 0 gravity's stiffness m g l sin θ is 0: Newton's matrix is singular there, and a
  // Levenberg–Marquardt step moves it on; the rest is θ = π/2 (hanging), not the upright −π/2.
  const StaticsResult r = solved(parse_spec(arm_json(0, 0, 9.81), "pendulum"));
  CHECK(std::abs(r.q[0] - std::numbers::pi / 2) < 1e-10);
}

TEST_CASE("statics refuses what it cannot solve, in one line", "[statics]") {
  // No spring and a torque beyond m g l: nothing holds the arm.
  StaticsOptions o;
  o.tau = VecX::Constant(1, 20.0);
  const StaticsResult r = solve_statics(parse_spec(arm_json(0, 0, 9.81), "arm"), o);
  CHECK_FALSE(r.status.ok);
  CHECK_THAT(r.status.message, Catch::StartsWith("no equilibrium found beyond load factor"));
  CHECK(r.status.message.find('\n') == std::string::npos);
}

// Closed loops: the rest of the five-bar, the delta robot and the hand's four-bars under
// gravity. Checked by other routes: the configuration closes the loops (|Φ| ≤ 1e-12 of the
// size), the constrained forward dynamics at rest there gives q̈ = 0 (to 1e-9 of g over the
// mechanism's size), and its multipliers carry the same joint forces Φ_qᵀ λ as the statics' μ.
TEST_CASE("statics finds the rest of closed loops, checked by the constrained dynamics",
          "[statics][loops]") {
  // (Bricard's linkage, whose five equations hold one redundant, from O = 0.5: from its neutral
  // posture Newton stalls, docs/loops.md#statics.)
  for (const char* name :
       {"five_bar.json", "delta.json", "hand_fourbar_loop.json", "iftomm_a04_bricard.json"}) {
    INFO(name);
    const MechanismSpec spec = parse_spec(read_file(model_path(name)), name);
    StaticsOptions o;
    if (std::string(name) == "iftomm_a04_bricard.json") {
      o.q0 = VecX::Zero(5);
      o.q0[0] = 0.5;
    }
    const StaticsResult r = solve_statics(spec, o);
    REQUIRE(r.status.ok);
    const Model m = compile(spec);
    Workspace ws(m);
    LoopWorkspace lws(m);
    ConstraintKinematics k(m);
    constraint_kinematics(m, ws, r.q, VecX::Zero(m.n()), k);
    double size = 0;
    for (const BodyState& B : ws.body) size = std::max(size, (B.p - ws.body.front().p).norm());
    CHECK(k.phi.cwiseAbs().maxCoeff() <= 1e-12 * size);
    CHECK(r.constraint_residual <= 1e-12 * size);
    const VecX zero = VecX::Zero(m.n());
    REQUIRE(mechanism_forward_dynamics(m, ws, &lws, r.q, zero, zero).ok);
    CHECK(ws.qdd.cwiseAbs().maxCoeff() < 1e-9 * m.gravity.norm() / size);
    const VecX forces = k.J.transpose() * r.multipliers, dynamics = k.J.transpose() * lws.lambda;
    CHECK((forces - dynamics).cwiseAbs().maxCoeff() < 1e-8 * r.scale);
    CHECK(r.residual <= 1e-10 * r.scale);
  }
}
