// Closed forms: single pendulum, planar double pendulum, and a gimbal whose asymmetric body
// makes the gyroscopic term matter — each against a hand derivation.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

TEST_CASE("single pendulum: M = m l², Q = −m g l sin θ, h = 0", "[closed-form]") {
  const Model m = load_model(model_path("pendulum.json"));
  Workspace ws(m);
  for (double th : {-2.0, -0.3, 0.0, 0.7, 2.9}) {
    VecX q(1), qd(1), tau(1);
    q << th;
    qd << 1.7;
    tau << 0.4;
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    evaluate(m, ws, q, qd, tau);
    CHECK_THAT(ws.Ms(0, 0), WithinRel(1.0, 1e-14));
    CHECK_THAT(ws.h[0], WithinAbs(0.0, 1e-14));
    CHECK_THAT(ws.Q[0], WithinAbs(-9.81 * std::sin(th) + 0.4, 1e-13));
    CHECK_THAT(ws.qdd[0], WithinAbs(-9.81 * std::sin(th) + 0.4, 1e-13));
  }
}

TEST_CASE("planar double pendulum of space bars matches the Lagrange closed form",
          "[closed-form]") {
  std::ifstream f(model_path("double_pendulum_planar.json"));
  const nlohmann::json spec = nlohmann::json::parse(f);
  const Model m = load_model(model_path("double_pendulum_planar.json"));
  // Parameters from the model file: bar i has mass m_i = ρ A l_i and centroidal inertia about
  // z, I_i = ρ l_i (I_z + A l_i²/12), its centroid at c_i = l_i / 2.
  double mass[2], len[2], Ic[2];
  for (int i = 0; i < 2; ++i) {
    const auto& e = spec["bodies"][i]["elements"][0];
    const double rho = e["density"], A = e["area"], Iz = e["Iz"];
    len[i] = spec["bodies"][i]["nodes"]["end"][0];
    mass[i] = rho * A * len[i];
    Ic[i] = rho * len[i] * (Iz + A * len[i] * len[i] / 12.0);
  }
  const double c1 = len[0] / 2, c2 = len[1] / 2, l1 = len[0], g = 9.81;
  Workspace ws(m);
  std::mt19937 rng(7);
  for (int k = 0; k < 10; ++k) {
    const VecX q = random_uniform(2, 3.0, rng), qd = random_uniform(2, 4.0, rng);
    REQUIRE(forward_dynamics(m, ws, q, qd, VecX::Zero(2)).ok);
    evaluate(m, ws, q, qd, VecX::Zero(2));
    const double s2 = std::sin(q[1]), cs2 = std::cos(q[1]);
    MatX M(2, 2);
    M(0, 0) = Ic[0] + mass[0] * c1 * c1 + Ic[1] + mass[1] * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * cs2);
    M(0, 1) = M(1, 0) = Ic[1] + mass[1] * (c2 * c2 + l1 * c2 * cs2);
    M(1, 1) = Ic[1] + mass[1] * c2 * c2;
    VecX h(2), Q(2);
    h[0] = -mass[1] * l1 * c2 * s2 * (2 * qd[0] * qd[1] + qd[1] * qd[1]);
    h[1] = mass[1] * l1 * c2 * s2 * qd[0] * qd[0];
    // V = g (m1 c1 sin θ1 + m2 (l1 sin θ1 + c2 sin(θ1+θ2))),  Q = −∂V/∂θ
    Q[0] = -g *
           ((mass[0] * c1 + mass[1] * l1) * std::cos(q[0]) + mass[1] * c2 * std::cos(q[0] + q[1]));
    Q[1] = -g * mass[1] * c2 * std::cos(q[0] + q[1]);
    CHECK(rel_error(ws.Ms, M) < 1e-13);
    CHECK(rel_error(ws.h, h) < 1e-12);
    CHECK(rel_error(ws.Q, Q) < 1e-13);
  }
  // The planar mechanism keeps only in-plane DOFs: x, y of the moving nodes and rz per body.
  CHECK(m.n_u() == 6);
}

TEST_CASE("gimbal: asymmetric body on yaw then pitch, gyroscopic terms by hand", "[closed-form]") {
  // Yaw ψ about world z, then pitch φ about the body x; body inertia diag(A, B, C) about the
  // joint intersection. ω_body = (φ̇, ψ̇ sin φ, ψ̇ cos φ), T = ½(A φ̇² + (B s² + C c²) ψ̇²):
  //   M = diag(B s² + C c², A),  h = (2 (B − C) s c φ̇ ψ̇,  −(B − C) s c ψ̇²)
  const double A = 0.03, B = 0.05, C = 0.025;
  const std::string json = R"({"name": "gimbal", "bodies": [
    {"name": "yoke", "parent": "world", "joint": {"name": "yaw", "type": "revolute", "axis": [0, 0, 1]}},
    {"name": "rotor", "parent": "yoke", "joint": {"name": "pitch", "type": "revolute", "axis": [1, 0, 0]},
     "elements": [{"type": "rotary_node", "node": [0, 0, 0],
                   "inertia": {"ixx": 0.03, "iyy": 0.05, "izz": 0.025}}]}]})";
  const Model m = load_text(json);
  REQUIRE(m.n() == 2);
  Workspace ws(m);
  std::mt19937 rng(11);
  for (int k = 0; k < 10; ++k) {
    VecX q = random_uniform(2, 3.0, rng), qd = random_uniform(2, 5.0, rng);
    q[1] = std::clamp(q[1], -1.2, 1.2);  // away from sin φ = 0, where M11 → C only
    evaluate(m, ws, q, qd, VecX());
    const double s = std::sin(q[1]), c = std::cos(q[1]);
    MatX M = MatX::Zero(2, 2);
    M(0, 0) = B * s * s + C * c * c;
    M(1, 1) = A;
    VecX h(2);
    h << 2 * (B - C) * s * c * qd[1] * qd[0], -(B - C) * s * c * qd[0] * qd[0];
    CHECK(rel_error(ws.Ms, M) < 1e-14);
    CHECK(rel_error(ws.h, h) < 1e-13);
  }
}
