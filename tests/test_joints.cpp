// The joint types of core/joints/ checked against what does not share their code: finite
// differences of body poses along each joint's own manifold (S and c_J against X_J), the node
// route against the body route (T = ∂u/∂v against the composite and Newton–Euler recursions),
// the symmetry and definiteness of M^s, and the conservation of energy and of momentum in free
// float by every integrator, with the quaternions' norm.
#include <catch2/catch.hpp>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "sim/integrator.hpp"
#include "sim/quintic.hpp"
#include "tests/helpers.hpp"
#include "tests/momentum.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A floating base carrying one child of every joint type (and a grandchild on the spherical
// one), rigid bodies with off-diagonal inertias and offset centres.
std::string all_joints_json(double gravity) {
  const auto body = [](const char* name, const char* parent, const char* joint, double m) {
    return std::string(R"({"name": ")") + name + R"(", "parent": ")" + parent + R"(", "joint": )" +
           joint + R"(, "elements": [{"type": "rigid_body", "mass": )" + std::to_string(m) +
           R"(, "com": [0.05, -0.02, 0.1], "inertia": {"ixx": 0.03, "iyy": 0.04, "izz": 0.05,
              "ixy": 0.002, "ixz": -0.001, "iyz": 0.003}}]})";
  };
  return std::string(R"({"name": "all joints", "gravity": [)") + std::to_string(0.03 * gravity) +
         ", " + std::to_string(-0.02 * gravity) + ", " + std::to_string(-gravity) +
         R"(], "bodies": [)" +
         body("base", "world", R"({"type": "free", "origin": {"rpy": [0.1, 0.2, 0.3]}})", 5.0) +
         "," +
         body("ball", "base",
              R"({"type": "spherical", "origin": {"xyz": [0.2, 0.1, 0.3], "rpy": [0.3, 0, 0.2]}})",
              1.5) +
         "," +
         body("cardan", "base",
              R"({"type": "universal", "axis": [1, 0, 0], "axis2": [0, 0.6, 0.8],
                  "origin": {"xyz": [-0.2, 0.1, 0.1], "rpy": [0, 0.4, 0]}})",
              1.2) +
         "," +
         body("slider", "base",
              R"({"type": "planar", "axis": [0, 1, 1], "origin": {"xyz": [0.1, -0.3, 0]}})", 0.9) +
         "," +
         body("screw", "ball",
              R"({"type": "helical", "axis": [0, 0, 1], "pitch": 0.05,
                  "origin": {"xyz": [0, 0, 0.4]}})",
              0.7) +
         "," +
         body("elbow", "cardan",
              R"({"type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.3, 0, 0]}})", 0.6) +
         "," +
         body("rail", "slider",
              R"({"type": "prismatic", "axis": [1, 0, 0], "origin": {"xyz": [0, 0, 0.2]}})", 0.4) +
         "]}";
}

VecX random_configuration(const Model& m, std::mt19937& rng) {
  VecX q(m.n_q());
  for (const Body& b : m.bodies)
    if (moves(b.joint)) femdyn::random_configuration(b.joint, rng, q.data() + b.joint.idx_q);
  return q;
}

// q ⊕ ξ over all joints (no couplings: θ = q).
VecX integrate(const Model& m, const VecX& q, const VecX& xi) {
  VecX out(m.n_q());
  for (const Body& b : m.bodies)
    if (const Joint& J = b.joint; moves(J))
      integrate_configuration(J, q.data() + J.idx_q, xi.data() + J.idx_v, out.data() + J.idx_q);
  return out;
}

// Every body's pose and the positions of the node level.
VecX node_positions(const Model& m, Workspace& ws, const VecX& q) {
  propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = false, .bias = false, .rows = false});
  VecX u(m.n_u());
  for (int i = 0; i < m.n_u(); ++i) u[i] = translation_value(m, ws, i);
  return u;
}

}  // namespace

TEST_CASE("every joint type compiles with its sizes, addresses and names") {
  const Model m = load_text(all_joints_json(9.81));
  CHECK(m.n() == 6 + 3 + 2 + 3 + 1 + 1 + 1);
  CHECK(m.n_q() == 7 + 4 + 2 + 3 + 1 + 1 + 1);
  CHECK(m.configuration_names[3] == "base.qw");
  CHECK(m.coordinate_names[0] == "base.vx");
  CHECK(m.coordinate_names[5] == "base.wz");
  CHECK(m.configuration_names[7] == "ball.qw");
  CHECK(m.coordinate_names[6] == "ball.wx");
}

TEST_CASE("a joint's motion subspace is the derivative of its pose along its manifold") {
  const Model m = load_text(all_joints_json(9.81));
  Workspace ws(m);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const VecX q = random_configuration(m, rng);
    propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = true, .bias = false, .rows = true});
    const MatX T = ws.T;
    // T e_k = (u(q ⊕ h e_k) − u(q ⊕ −h e_k)) / 2h, O(h²)
    const double h = 1e-6;
    for (int k = 0; k < m.n(); ++k) {
      const VecX e = VecX::Unit(m.n(), k);
      const VecX fd = (node_positions(m, ws, integrate(m, q, h * e)) -
                       node_positions(m, ws, integrate(m, q, -h * e))) /
                      (2 * h);
      // rotation rows of u are not positions: compare translation rows only
      for (int i = 0; i < m.n_u(); ++i)
        if (m.dofs[i].kind == DofKind::Translation)
          CHECK(std::abs(T(i, k) - fd[i]) < 1e-7 * (1 + std::abs(fd[i])));
    }
  }
}

namespace {

// u along the motion at constant rates v from q: ξ(t) with ξ̇ = chart rate(ξ, v), by RK4 in
// 20 small steps (the curve, not the integrators under test).
VecX along(const Model& m, const VecX& q, const VecX& v, double t) {
  const auto rate = [&](const VecX& xi) {
    VecX d(m.n());
    for (const Body& b : m.bodies)
      if (const Joint& J = b.joint; moves(J))
        chart_rate(J, q.data() + J.idx_q, xi.data() + J.idx_v, v.data() + J.idx_v,
                   d.data() + J.idx_v);
    return d;
  };
  VecX xi = VecX::Zero(m.n());
  const int steps = 20;
  const double h = t / steps;
  for (int s = 0; s < steps; ++s) {
    const VecX k1 = rate(xi), k2 = rate(xi + h / 2 * k1), k3 = rate(xi + h / 2 * k2),
               k4 = rate(xi + h * k3);
    xi += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return integrate(m, q, xi);
}

}  // namespace

TEST_CASE("a joint's bias c_J is the second derivative of the motion at constant rates") {
  const Model m = load_text(all_joints_json(9.81));
  Workspace ws(m);
  std::mt19937 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const VecX q = random_configuration(m, rng);
    const VecX v = random_uniform(m.n(), 1.0, rng);
    propagate(m, ws, q, v, {.jacobian = false, .bias = true, .rows = false});
    const VecX bias = ws.bias.head(m.n_u());
    const double h = 1e-3;
    const VecX u0 = node_positions(m, ws, q), up = node_positions(m, ws, along(m, q, v, h)),
               um = node_positions(m, ws, along(m, q, v, -h));
    const VecX fd = (up - 2 * u0 + um) / (h * h);  // O(h²) ≈ 1e-6 relative
    for (int i = 0; i < m.n_u(); ++i)
      if (m.dofs[i].kind == DofKind::Translation)
        CHECK(std::abs(bias[i] - fd[i]) < 1e-5 * (1 + std::abs(fd[i])));
  }
}

TEST_CASE("the node route and the body routes agree for every joint type") {
  const Model nodes =
      load_text(all_joints_json(9.81),
                {.routes = {.mass = MassRoute::Transform, .force = ForceRoute::Nodes}});
  const Model bodies = load_text(all_joints_json(9.81));
  REQUIRE(bodies.condensable);
  Workspace wn(nodes), wb(bodies);
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const VecX q = random_configuration(nodes, rng);
    const VecX v = random_uniform(nodes.n(), 1.0, rng), tau = random_uniform(nodes.n(), 1.0, rng);
    evaluate(nodes, wn, q, v, tau);
    evaluate(bodies, wb, q, v, tau);
    CHECK(rel_error(wn.Ms, wb.Ms) < 1e-12);
    CHECK(rel_error(wn.h, wb.h) < 1e-12);
    CHECK(rel_error(wn.Q, wb.Q) < 1e-12);
    CHECK(rel_error(wn.Ms, wn.Ms.transpose()) < 1e-14);
    CHECK(Eigen::LLT<MatX>(wn.Ms).info() == Eigen::Success);
    REQUIRE(forward_dynamics(bodies, wb, q, v, tau).ok);
    const VecX qdd = wb.qdd;
    CHECK(rel_error(wn.Ms * qdd + wn.h, wn.Q) < 1e-11);
    inverse_dynamics(bodies, wb, q, v, qdd);
    CHECK(rel_error(wb.tau, tau) < 1e-10);
  }
}

TEST_CASE("the quintic reference's v and v̇ are its derivatives on every joint's manifold") {
  // q(t) = q0 ⊕ s(t)Δ: v is the rate of the chart around q(t) (whose ξ̇ at ξ = 0 is v), and v̇
  // the rate of v, both against central differences (O(h²)).
  const Model m = load_text(all_joints_json(9.81));
  std::mt19937 rng(11);
  const VecX q0 = random_configuration(m, rng), q1 = random_configuration(m, rng);
  const VecX delta = configuration_difference(m, q0, q1);
  VecX q, v, vdot, qa, va, ad, qb, vb, bd;
  const double T = 0.8, h = 1e-5;
  quintic(m, q0, delta, T, T, q, v, vdot);
  CHECK(configuration_difference(m, q, q1).norm() < 1e-12);  // it ends at q1
  for (const double t : {0.13, 0.4, 0.71}) {
    quintic(m, q0, delta, T, t, q, v, vdot);
    quintic(m, q0, delta, T, t + h, qa, va, ad);
    quintic(m, q0, delta, T, t - h, qb, vb, bd);
    const VecX v_fd =
        (configuration_difference(m, q, qa) - configuration_difference(m, q, qb)) / (2 * h);
    const VecX vdot_fd = (va - vb) / (2 * h);
    INFO("t = " << t);
    CHECK((v - v_fd).cwiseAbs().maxCoeff() < 1e-8 * (1 + v.cwiseAbs().maxCoeff()));
    CHECK((vdot - vdot_fd).cwiseAbs().maxCoeff() < 1e-7 * (1 + vdot.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("in free float every integrator keeps the quaternions unit, dopri conserves momentum") {
  const Model m = load_text(all_joints_json(0.0));
  Workspace ws(m);
  std::mt19937 rng(5);
  const VecX q0 = random_configuration(m, rng), v0 = random_uniform(m.n(), 2.0, rng);
  const Vec6 h0 = momentum(m, ws, q0, v0);
  const double E0 = energy(m, ws, q0, v0).total();
  for (IntegratorKind kind : kIntegrators) {
    IntegratorOptions o;
    o.kind = kind;
    o.fixed.dt = 1e-3;
    o.adaptive.rtol = 1e-11;
    o.adaptive.atol = 1e-12;
    auto integrator = make_integrator(m, o);
    integrator->reset(0, q0, v0);
    REQUIRE(integrator->advance_to(2.0).ok);
    const VecX q = integrator->q(), v = integrator->qd();
    INFO(integrator->name());
    for (const Body& b : m.bodies)
      if (!is_flat(b.joint))
        CHECK(std::abs(q.segment<4>(b.joint.idx_q + b.joint.nq - 4).norm() - 1) < 1e-14);
    const Vec6 h = momentum(m, ws, q, v);
    if (kind == IntegratorKind::Dopri) {
      CHECK((h - h0).norm() < 1e-9 * h0.norm());
      CHECK(std::abs(energy(m, ws, q, v).total() - E0) < 1e-9 * std::abs(E0));
    }
    if (kind == IntegratorKind::Rk4) CHECK((h - h0).norm() < 1e-6 * h0.norm());
  }
}

TEST_CASE("under gravity the energy of the free mechanism is conserved by dopri") {
  const Model m = load_text(all_joints_json(9.81));
  Workspace ws(m);
  std::mt19937 rng(9);
  const VecX q0 = random_configuration(m, rng), v0 = random_uniform(m.n(), 1.0, rng);
  IntegratorOptions o;
  o.kind = IntegratorKind::Dopri;
  o.adaptive.rtol = 1e-11;
  o.adaptive.atol = 1e-12;
  auto integrator = make_integrator(m, o);
  integrator->reset(0, q0, v0);
  REQUIRE(integrator->advance_to(1.0).ok);
  const double E0 = energy(m, ws, q0, v0).total();
  const double E1 = energy(m, ws, integrator->q(), integrator->qd()).total();
  const double scale = energy(m, ws, q0, v0).kinetic + 5.0 * 9.81;
  CHECK(std::abs(E1 - E0) < 1e-8 * scale);
}
