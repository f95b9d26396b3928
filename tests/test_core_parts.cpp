// Direct tests of core's building blocks that the public equations use but no other test
// includes (tools/test_map.py lists which test covers each core header): each against an
// independent number — an identity, another route, differences or a closed form.
//   core/derivatives/inverse_mass.hpp   (M^s)⁻¹ M^s = I on every route, and −(M^s)⁻¹ ∂τ/∂·
//   core/dynamics/newton_euler.hpp      the body-level τ equals the node-level route's
//   core/kinematics/coupling.hpp        C and Cᵀ are adjoint, and equal the dense C
//   core/joints/rotor.hpp               no work, its tensor and its rate derivative
//   core/model/prescribed_motion.hpp    q̇, q̈ against differences of q, q̇; continuity
//   core/model/joint_type.hpp, core/model/loop_constraint.hpp   names round trip
//   core/spatial/math.hpp               skew, rotations, the mirror, point inertia
#include <catch2/catch.hpp>
#include <random>

#include "core/derivatives/derivatives.hpp"
#include "core/derivatives/inverse_mass.hpp"
#include "core/dynamics/equations.hpp"
#include "core/dynamics/newton_euler.hpp"
#include "core/joints/rotor.hpp"
#include "core/kinematics/coupling.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/joint_type.hpp"
#include "core/model/loop_constraint.hpp"
#include "core/model/prescribed_motion.hpp"
#include "core/spatial/math.hpp"
#include "core/workspace/workspace.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// (M^s)⁻¹ M^s = I, and ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂· (the product on the runs of ∂τ/∂·'s pattern, or
// by the factorisation above n = 96) against a dense solve.
void check_inverse_mass(const Model& m, unsigned seed) {
  Workspace ws(m);
  DerivativeWorkspace d(m);
  std::mt19937 rng(seed);
  const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
  evaluate(m, ws, q, v, VecX::Zero(m.n()));
  const MatX Ms = ws.Ms;
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, VecX::Zero(m.n())).ok);
  INFO("seed " << seed << ", n " << m.n() << ", sweep " << d.sweep.applies);
  CHECK(rel_error(d.Minv * Ms, MatX::Identity(m.n(), m.n())) < 1e-10);
  const auto solve = Ms.ldlt();
  CHECK(rel_error(d.dqdd_dq, -solve.solve(d.dtau_dq)) < 1e-10);
  CHECK(rel_error(d.dqdd_dv, -solve.solve(d.dtau_dv)) < 1e-10);
}

}  // namespace

TEST_CASE("core parts: (M^s)^-1 from the factorisation inverts M^s on every route") {
  for (unsigned seed = 1; seed <= 6; ++seed)
    for (const RouteChoice& routes : main_routes())
      check_inverse_mass(
          load_text(mixed_tree_json(seed, 9, 0.5, seed % 3 == 0, seed % 3 != 0), {routes}), seed);
  check_inverse_mass(load_text(random_tree_json(7, 110, 0.3, true)), 7);  // n > 96
}

TEST_CASE("core parts: Newton-Euler's tau equals the node-level route's inverse dynamics") {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const std::string text = random_tree_json(seed, 10, 0.4, true);
    const Model bodies = load_text(text, {{.force = ForceRoute::Bodies}});
    const Model nodes =
        load_text(text, {{.mass = MassRoute::Transform, .force = ForceRoute::Nodes}});
    REQUIRE(bodies.force_route == ForceRoute::Bodies);
    Workspace wb(bodies), wn(nodes);
    std::mt19937 rng(seed);
    const VecX q = random_posture(bodies, rng), v = random_uniform(bodies.n(), 1.5, rng),
               a = random_uniform(bodies.n(), 2.0, rng);
    VecX tau;
    newton_euler(bodies, wb, q, v, &a, true, tau);
    inverse_dynamics(nodes, wn, q, v, a);
    INFO("seed " << seed);
    CHECK(rel_error(tau, wn.tau) < 1e-12);
    // q̈ = nullptr is q̈ = 0.
    newton_euler(bodies, wb, q, v, nullptr, true, tau);
    inverse_dynamics(nodes, wn, q, v, VecX::Zero(nodes.n()));
    CHECK(rel_error(tau, wn.tau) < 1e-12);
  }
}

TEST_CASE("core parts: the coupling's C and its transpose are adjoint and equal the dense C") {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const Model m = load_text(mixed_tree_json(seed, 10, 0.4, true));
    REQUIRE_FALSE(m.identity_coupling);
    std::mt19937 rng(seed);
    const VecX x = random_uniform(m.n(), 1.0, rng), f = random_uniform(m.n_theta(), 1.0, rng);
    VecX Cx, Ctf;
    coupling_apply(m, x, Cx);
    coupling_apply_transpose(m, f, Ctf);
    CHECK(std::abs(Cx.dot(f) - x.dot(Ctf)) < 1e-12 * (1 + std::abs(Cx.dot(f))));
    CHECK(max_abs(Cx - MatX(m.C) * x) < 1e-14);
    VecX rows = VecX::Zero(m.n());  // Σ_j f_j (row j of C)ᵀ = Cᵀ f
    for (int j = 0; j < m.n_theta(); ++j) coupling_add_row(m, j, f[j], rows);
    CHECK(max_abs(rows - Ctf) < 1e-14);
  }
}

TEST_CASE("core parts: a free joint's rotor does no work, and its tensor and rate derivative") {
  const Model m = load_text(R"({"name": "rotor", "gravity": [0, 0, 0], "bodies": [
    {"name": "b", "parent": "world", "joint": {"type": "free", "armature": 0.3},
     "elements": [{"type": "rigid_body", "mass": 2, "inertia": {"ixx": 0.1, "iyy": 0.2, "izz": 0.3}}]}]})");
  REQUIRE(m.free_rotors.size() == 1);
  std::mt19937 rng(4);
  const VecX v = random_uniform(m.n(), 2.0, rng);
  VecX h = VecX::Zero(m.n());
  add_rotor_bias(m, v, 1.0, h);
  CHECK(h.norm() > 0.1);
  CHECK(std::abs(v.dot(h)) < 1e-14);  // q̇ᵀ h_a = a v·(ω × v) = 0
  std::vector<MatX> D(m.n(), MatX::Zero(m.n(), m.n()));
  add_rotor_bias_tensor(m, D);
  for (int k = 0; k < m.n(); ++k) CHECK(std::abs(v.dot(D[k] * v) - h[k]) < 1e-14);
  // ∂h_a/∂q̇ by central differences (h_a is quadratic: exact up to round-off).
  MatX K = MatX::Zero(m.n(), m.n()), Kd(m.n(), m.n());
  add_rotor_bias_rate_derivative(m, v, K);
  for (int c = 0; c < m.n(); ++c) {
    VecX hp = VecX::Zero(m.n()), hm = VecX::Zero(m.n()), e = VecX::Unit(m.n(), c) * 1e-3;
    add_rotor_bias(m, v + e, 1.0, hp);
    add_rotor_bias(m, v - e, 1.0, hm);
    Kd.col(c) = (hp - hm) / 2e-3;
  }
  CHECK(max_abs(K - Kd) < 1e-12);
}

TEST_CASE("core parts: a prescribed motion's rates are the derivatives of its value") {
  PrescribedMotion spin{.kind = PrescribedMotion::Kind::SpinUp, .rate = 4, .time = 15};
  PrescribedMotion poly{.coefficients = {0.2, -1, 0.5, 0.3, -0.05}};
  const double h = 1e-5;
  for (const PrescribedMotion& p : {spin, poly})
    for (double t : {0.3, 2.0, 7.5, 14.2, 20.0}) {
      const auto at = p.at(t), up = p.at(t + h), down = p.at(t - h);
      // Truncation h²/6 |d³q/dt³| ≈ 1e-10; the differences' round-off 4 ε |q| / h.
      const auto tol = [&](double x) { return 1e-9 + 4 * 2.2e-16 * std::abs(x) / h; };
      INFO("t " << t);
      CHECK(std::abs((up[0] - down[0]) / (2 * h) - at[1]) < tol(at[0]));
      CHECK(std::abs((up[1] - down[1]) / (2 * h) - at[2]) < tol(at[1]));
    }
  // Value, rate and acceleration continuous where the spin-up ends (q̈ → 0 and q̇ → ω_s).
  const auto before = spin.at(15 - 1e-9), after = spin.at(15 + 1e-9);
  for (int k = 0; k < 3; ++k) CHECK(std::abs(before[k] - after[k]) < 1e-7);
  CHECK(after[0] == Approx(4 * (15 + 1e-9 - 7.5)).epsilon(1e-12));
  // The polynomial by Horner equals the sum.
  const double t = 1.7;
  double sum = 0;
  for (std::size_t k = 0; k < poly.coefficients.size(); ++k)
    sum += poly.coefficients[k] * std::pow(t, static_cast<double>(k));
  CHECK(poly.at(t)[0] == Approx(sum).epsilon(1e-14));
}

TEST_CASE("core parts: joint and constraint type names round trip") {
  for (const JointTypeName& t : kJointTypeNames) {
    CHECK(joint_type_named(t.name) == t.type);
    CHECK(joint_type_named(joint_type_name(t.type)) == t.type);
    CHECK(joint_type_list().find(t.name) != std::string::npos);
  }
  CHECK_FALSE(joint_type_named("hinge").has_value());
  for (ConstraintType c :
       {ConstraintType::Ball, ConstraintType::Weld, ConstraintType::Distance,
        ConstraintType::PointOnLine, ConstraintType::PointOnPlane, ConstraintType::Gear}) {
    ConstraintType back{};
    CHECK(parse_constraint_type(constraint_type_name(c), back));
    CHECK(back == c);
  }
  ConstraintType none{};
  CHECK_FALSE(parse_constraint_type("rope", none));
}

TEST_CASE("core parts: skew, rotations, the mirror and the point inertia") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), rpy(u(rng), u(rng), u(rng));
  CHECK(max_abs(skew(a) * b - a.cross(b)) < 1e-15);
  CHECK(max_abs(cross3(a, b) - a.cross(b)) < 1e-15);
  const Mat3 R = rpy_to_rotation(rpy);  // URDF: Rz(yaw) Ry(pitch) Rx(roll)
  CHECK(max_abs(R * R.transpose() - Mat3::Identity()) < 1e-15);
  CHECK(R.determinant() == Approx(1).epsilon(1e-14));
  const Mat3 Rz = axis_rotation(Vec3::UnitZ(), rpy.z()), Ry = axis_rotation(Vec3::UnitY(), rpy.y()),
             Rx = axis_rotation(Vec3::UnitX(), rpy.x());
  CHECK(max_abs(R - Rz * Ry * Rx) < 1e-15);
  const Vec3 n = a.normalized();
  CHECK(max_abs(axis_rotation(n, 0.7) * n - n) < 1e-15);
  CHECK(std::acos((axis_rotation(n, 0.7).trace() - 1) / 2) == Approx(0.7).epsilon(1e-12));
  // I_o = m [r]xᵀ[r]x.
  CHECK(max_abs(point_inertia(2.5, a) - 2.5 * skew(a).transpose() * skew(a)) < 1e-15);
  for (int n_rows : {5, 40, 300}) {  // both tile sizes
    MatX A = MatX::Random(n_rows, n_rows);
    MatX upper = A.triangularView<Eigen::Upper>();
    mirror_upper(A);
    CHECK(max_abs(A - A.transpose()) == 0);
    CHECK(max_abs(MatX(A.triangularView<Eigen::Upper>()) - upper) == 0);
  }
}
