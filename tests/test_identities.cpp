// Identities on seeded random trees: T and T'[q̇,q̇] against finite differences of u(q), the
// Christoffel symbols from finite differences of M^s, Ṁ^s − 2C skew, M^s SPD, energy.
#include <catch2/catch.hpp>
#include <cmath>

#include "sim/fixed_step.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// vee(S) for a skew matrix S = [w]×.
Vec3 vee(const Mat3& S) {
  return Vec3(S(2, 1) - S(1, 2), S(0, 2) - S(2, 0), S(1, 0) - S(0, 1)) / 2;
}

struct Case {
  unsigned seed;
  int bodies;
  double branching;
};
const Case kCases[] = {{1, 3, 0.0}, {2, 6, 0.5}, {3, 9, 1.0}, {4, 12, 0.3}};

// T and T'[q̇,q̇] (and the full T') against central differences of u(q), at 3 random states.
void check_transform(const Model& m, std::mt19937& rng) {
  Workspace ws(m), wp(m), wm(m);
  const int n = m.n(), N = m.n_u();
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_uniform(n, 2.0, rng), qd = random_uniform(n, 1.5, rng);
    propagate(m, ws, q, qd, {.jacobian = true, .bias = true});
    const double eps = 1e-6;
    // T by columns: translations from positions, rotations from vee(Rᵀ ∂R/∂q_a).
    MatX T_fd(N, n);
    for (int a = 0; a < n; ++a) {
      VecX qp = q, qm = q;
      qp[a] += eps;
      qm[a] -= eps;
      propagate(m, wp, qp, qd, {.jacobian = false, .bias = false});
      propagate(m, wm, qm, qd, {.jacobian = false, .bias = false});
      for (int i = 0; i < N; ++i) {
        const SystemDof& d = m.dofs[i];
        if (d.kind == DofKind::Translation) {
          T_fd(i, a) = (translation_value(m, wp, i) - translation_value(m, wm, i)) / (2 * eps);
        } else {
          const Mat3 R = ws.body[d.carrier].R;
          const Mat3 dR = (wp.body[d.carrier].R - wm.body[d.carrier].R) / (2 * eps);
          T_fd(i, a) = vee(R.transpose() * dR)[d.axis];
        }
      }
    }
    CHECK(rel_error(ws.T, T_fd) < 1e-8);
    // T'[q̇,q̇] = d/dε (T(q + ε q̇) q̇) at ε = 0.
    propagate(m, wp, q + eps * qd, qd, {.jacobian = true, .bias = false});
    propagate(m, wm, q - eps * qd, qd, {.jacobian = true, .bias = false});
    const VecX bias_fd = (wp.T * qd - wm.T * qd) / (2 * eps);
    CHECK(rel_error(ws.bias, bias_fd) < 1e-7);
    // u̇ = T q̇
    CHECK(rel_error(ws.u_dot, ws.T * qd) < 1e-14);
    // Full T'_{·bc} = ∂T_{·b}/∂q_c (not symmetric on rotation rows) against differences of T.
    if (k == 0) {
      const std::vector<MatX> Tp = transform_hessian(m, ws, q);
      double worst = 0, scale = 0;
      for (int cc = 0; cc < n; ++cc) {
        VecX qp = q, qm = q;
        qp[cc] += eps;
        qm[cc] -= eps;
        propagate(m, wp, qp, qd, {.jacobian = true, .bias = false});
        propagate(m, wm, qm, qd, {.jacobian = true, .bias = false});
        const MatX dT = (wp.T - wm.T) / (2 * eps);
        for (int i = 0; i < N; ++i)
          for (int b = 0; b < n; ++b) {
            worst = std::max(worst, std::abs(Tp[i](b, cc) - dT(i, b)));
            scale = std::max(scale, std::abs(dT(i, b)));
          }
      }
      CHECK(worst < 1e-7 * scale);
    }
  }
}

// sym(D) = Christoffel symbols of M^s (central differences), h = D[q̇,q̇], Ṁ − 2C skew, M^s SPD.
void check_tensor(const Model& m, std::mt19937& rng) {
  Workspace ws(m), wp(m), wm(m);
  const int n = m.n();
  const VecX q = random_uniform(n, 2.0, rng), qd = random_uniform(n, 1.5, rng);
  const std::vector<MatX> D = third_order_tensor(m, ws, q);
  // ∂M^s/∂q_c by central differences.
  const double eps = 1e-6;
  std::vector<MatX> dM(n);
  for (int a = 0; a < n; ++a) {
    VecX qp = q, qm = q;
    qp[a] += eps;
    qm[a] -= eps;
    evaluate(m, wp, qp, VecX::Zero(n), VecX());
    evaluate(m, wm, qm, VecX::Zero(n), VecX());
    dM[a] = (wp.Ms - wm.Ms) / (2 * eps);
  }
  double scale = 0, worst = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      for (int cc = 0; cc < n; ++cc) {
        // Γ_abc = ½(∂_c M_ab + ∂_b M_ac − ∂_a M_bc)
        const double gamma = 0.5 * (dM[cc](a, b) + dM[b](a, cc) - dM[a](b, cc));
        const double symD = 0.5 * (D[a](b, cc) + D[a](cc, b));
        worst = std::max(worst, std::abs(symD - gamma));
        scale = std::max(scale, std::abs(gamma));
      }
  CHECK(worst < 1e-7 * scale);
  // h = D[q̇,q̇]
  evaluate(m, ws, q, qd, VecX());
  VecX hD(n);
  for (int a = 0; a < n; ++a) hD[a] = qd.dot(D[a] * qd);
  CHECK(rel_error(hD, ws.h) < 1e-12);
  // C_ab = Σ_c D_abc q̇_c; Ṁ^s = Σ_c ∂_c M^s q̇_c; Ṁ^s − 2C skew.
  MatX Cm(n, n), Mdot = MatX::Zero(n, n);
  for (int a = 0; a < n; ++a) Cm.row(a) = (D[a] * qd).transpose();
  for (int cc = 0; cc < n; ++cc) Mdot += dM[cc] * qd[cc];
  const MatX S = Mdot - 2 * Cm;
  CHECK((S + S.transpose()).cwiseAbs().maxCoeff() < 1e-7 * Mdot.cwiseAbs().maxCoeff());
  // M^s symmetric positive definite.
  CHECK((ws.Ms - ws.Ms.transpose()).cwiseAbs().maxCoeff() < 1e-15 * ws.Ms.norm());
  CHECK(Eigen::SelfAdjointEigenSolver<MatX>(ws.Ms).eigenvalues().minCoeff() > 0);
}

}  // namespace

TEST_CASE("T = ∂u/∂q and T'[q̇,q̇] match central differences on random trees", "[identity]") {
  for (const Case& c : kCases) {
    const Model m = load_text(random_tree_json(c.seed, c.bodies, c.branching, true));
    std::mt19937 rng(c.seed + 100);
    check_transform(m, rng);
  }
}

TEST_CASE("sym(D) equals the Christoffel symbols of M^s, h = D[q̇,q̇], Ṁ − 2C is skew",
          "[identity]") {
  for (const Case& c : kCases) {
    const Model m = load_text(random_tree_json(c.seed + 10, c.bodies, c.branching, true));
    std::mt19937 rng(c.seed + 200);
    check_tensor(m, rng);
  }
}

TEST_CASE("T, T' and the tensor identities hold with nonlinear couplings", "[identity][coupling]") {
  for (unsigned seed : {5u, 6u}) {
    const Model m = load_text(nonlinear_coupled_tree_json(seed));
    REQUIRE(m.coupling_level);
    REQUIRE(m.n() == 3);
    std::mt19937 rng(seed);
    check_transform(m, rng);
    check_tensor(m, rng);
  }
}

TEST_CASE("energy is conserved by a conservative model (RK4, tight step)", "[identity]") {
  // Spring + gravity, no damping: E = ½ q̇ᵀ M^s q̇ + V must stay constant.
  for (unsigned seed : {21u, 22u}) {
    const Model m = load_text(random_tree_json(seed, 5, 0.5, true));
    const int n = m.n();
    std::mt19937 rng(seed);
    const VecX q0 = random_uniform(n, 1.0, rng), v0 = random_uniform(n, 1.0, rng);
    Rk4 rk4(m, {.dt = 2e-4});
    rk4.reset(0, q0, v0);
    const double E0 = rk4.motion().energy_at(rk4.y().data()).total();
    double drift = 0, scale = 0;
    for (int step = 0; step < 2500; ++step) {  // 0.5 s
      REQUIRE(rk4.step().ok);
      const Energy E = rk4.motion().energy_at(rk4.y().data());
      drift = std::max(drift, std::abs(E.total() - E0));
      scale = std::max(scale, E.kinetic);
    }
    INFO("seed " << seed << " drift " << drift << " max kinetic " << scale);
    CHECK(scale > 1e-2);  // it really moved
    CHECK(drift < 1e-8 * scale);
  }
}

TEST_CASE("loads and springs: Q is the virtual work of the applied forces", "[identity]") {
  // Force F at point p of body c, torque τ on body b, spring and damper on joint j2:
  //   Q_a = F · ∂p/∂q_a + τ · w_a − k (θ − θ_rest) ∂θ/∂q_a − c θ̇ ∂θ/∂q_a,
  // with ∂p/∂q_a and the world angular Jacobian w_a = vee(∂R/∂q_a Rᵀ) by central differences.
  const std::string json = R"({"name": "loads", "bodies": [
    {"name": "a", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "lumped_point", "node": [0.4, 0, 0], "mass": 1}]},
    {"name": "b", "parent": "a", "joint": {"name": "j2", "type": "revolute", "axis": [0, 1, 0.3],
     "origin": {"xyz": [0.4, 0, 0], "rpy": [0.2, 0, 0.1]}, "spring": {"stiffness": 3.0, "rest": 0.2},
     "damping": 0.7},
     "elements": [{"type": "lumped_point", "node": [0.3, 0.1, 0], "mass": 1}]},
    {"name": "c", "parent": "b", "joint": {"name": "j3", "type": "prismatic", "axis": [1, 0, 0],
     "origin": {"xyz": [0.3, 0, 0]}},
     "elements": [{"type": "lumped_point", "node": [0.1, 0, 0.05], "mass": 1}]}],
    "loads": [{"body": "c", "point": [0.2, -0.1, 0.05], "force": [1.0, -2.0, 0.5]},
              {"body": "b", "torque": [0.3, 0.2, -0.4]}]})";
  const Model m = load_text(json);
  Workspace ws(m), wp(m), wm(m);
  std::mt19937 rng(8);
  const Vec3 F(1.0, -2.0, 0.5), tau(0.3, 0.2, -0.4), p_c(0.2, -0.1, 0.05);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(3, 2, rng), qd = random_uniform(3, 2, rng);
    evaluate(m, ws, q, qd, VecX());
    VecX Q(3);
    for (int a = 0; a < 3; ++a) {
      const double eps = 1e-6;
      VecX qp = q, qm = q;
      qp[a] += eps;
      qm[a] -= eps;
      propagate(m, wp, qp, qd, {.jacobian = false, .bias = false});
      propagate(m, wm, qm, qd, {.jacobian = false, .bias = false});
      const Vec3 dp = ((wp.origin + wp.body[2].p + wp.body[2].R * p_c) -
                       (wm.origin + wm.body[2].p + wm.body[2].R * p_c)) /
                      (2 * eps);
      const Mat3 W = (wp.body[1].R - wm.body[1].R) / (2 * eps) * ws.body[1].R.transpose();
      const Vec3 w(W(2, 1), W(0, 2), W(1, 0));
      Q[a] = F.dot(dp) + tau.dot(w);
    }
    Q[1] += -3.0 * (q[1] - 0.2) - 0.7 * qd[1];
    CHECK(rel_error(ws.Q, Q) < 1e-8);
  }
}
