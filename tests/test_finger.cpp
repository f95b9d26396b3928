// The dexterous finger: the paper's N_m and diagonal mass entry by entry; the planar special
// case (θ1 fixed) against a hand-derived planar 3-link arm; the coupled finger's reduction.
#include <catch2/catch.hpp>
#include <cmath>

#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

const double a[4] = {0.015, 0.045, 0.030, 0.022};   // lengths
const double w[4] = {0.012, 0.012, 0.011, 0.010};   // widths (along the flexion axis)
const double hh[4] = {0.010, 0.010, 0.009, 0.008};  // heights
const double rho = 2700;

std::string finger_json(const std::string& extra) {
  return R"({"model": "dexterous_finger", "params": {"lengths": [0.015, 0.045, 0.030, 0.022],
    "width": [0.012, 0.012, 0.011, 0.010], "height": [0.010, 0.010, 0.009, 0.008],
    "density": 2700)" +
         extra + "}}";
}

}  // namespace

TEST_CASE("the paper's N_m and diagonal system mass are reproduced entry by entry", "[finger]") {
  const Model m = load_text(finger_json(R"(, "lumping": "paper")"));
  const int paper[4][12] = {{0, 0, 0, 0, 0, 1, 2, 3, 0, 4, 0, 0},
                            {2, 3, 0, 4, 0, 0, 5, 6, 7, 8, 0, 0},
                            {5, 6, 7, 8, 0, 0, 9, 10, 11, 12, 0, 0},
                            {9, 10, 11, 12, 0, 0, 13, 14, 15, 16, 0, 0}};
  REQUIRE(m.elements.size() == 4);
  REQUIRE(m.n_u() == 16);
  for (int e = 0; e < 4; ++e)
    for (int l = 0; l < 12; ++l) CHECK(m.elements[e].table_row[l] == paper[e][l]);
  // [M] = ½ diag[J1z, m1+m2, m1+m2, J1x+J2x, m2+m3 (×3), J2x+J3x, m3+m4 (×3), J3x+J4x,
  //             m4 (×3), J4x],   m = ρ A l,  J_x = ⅙ ρ l (I_y + I_z),  J_z = ρ l (I_z − A l²/6)
  double mk[4], Jx[4];
  for (int k = 0; k < 4; ++k) {
    const double A = w[k] * hh[k], Iy = w[k] * std::pow(hh[k], 3) / 12,
                 Iz = hh[k] * std::pow(w[k], 3) / 12;
    mk[k] = rho * A * a[k];
    Jx[k] = rho * a[k] * (Iy + Iz) / 6;
  }
  const double A1 = w[0] * hh[0], I1z = hh[0] * std::pow(w[0], 3) / 12;
  const double J1z = rho * a[0] * (I1z - A1 * a[0] * a[0] / 6);
  const double diag[16] = {J1z,           mk[0] + mk[1], mk[0] + mk[1], Jx[0] + Jx[1],
                           mk[1] + mk[2], mk[1] + mk[2], mk[1] + mk[2], Jx[1] + Jx[2],
                           mk[2] + mk[3], mk[2] + mk[3], mk[2] + mk[3], Jx[2] + Jx[3],
                           mk[3],         mk[3],         mk[3],         Jx[3]};
  const MatX M = MatX(m.M);
  for (int i = 0; i < 16; ++i) {
    INFO("diagonal entry " << i + 1);
    CHECK(std::abs(M(i, i) - 0.5 * diag[i]) <= 1e-15 * std::abs(diag[i]));
  }
  CHECK((M - MatX(M.diagonal().asDiagonal())).cwiseAbs().maxCoeff() == 0.0);
  // The paper's u (first, consistent form): u1 = θ1 rate, u4 = θ2, u8 = θ2+θ3, u12 = u16 =
  // θ2+θ3+θ4.
  Workspace ws(m);
  VecX q(4);
  q << 0.3, 0.4, 0.5, 0.6;
  propagate(m, ws, q, VecX::Zero(4), {.jacobian = true, .bias = false});  // forms T
  MatX Trot(5, 4);
  Trot << 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1, 0, 0, 1, 1, 1, 0, 1, 1, 1;
  const int rot_rows[5] = {0, 3, 7, 11, 15};
  for (int r = 0; r < 5; ++r) CHECK((ws.T.row(rot_rows[r]) - Trot.row(r)).norm() < 1e-15);
  // u5..u7: the proximal end at ((a2 s2 + a1) c1, (a2 s2 + a1) s1, a2 c2).
  const double s1 = std::sin(q[0]), c1 = std::cos(q[0]), s2 = std::sin(q[1]), c2 = std::cos(q[1]);
  const Vec3 p(((a[1] * s2 + a[0]) * c1), (a[1] * s2 + a[0]) * s1, a[1] * c2);
  for (int k = 0; k < 3; ++k) CHECK(std::abs(translation_value(m, ws, 4 + k) - p[k]) < 1e-15);
  // u13..u15, the fingertip, with the paper's u15 corrected (it prints a2 c2 twice):
  // ((a4 s234 + a3 s23 + a2 s2 + a1) c1, (…) s1, a2 c2 + a3 c23 + a4 c234).
  const double t23 = q[1] + q[2], t234 = t23 + q[3];
  const double r = a[3] * std::sin(t234) + a[2] * std::sin(t23) + a[1] * s2 + a[0];
  const Vec3 tip(r * c1, r * s1, a[1] * c2 + a[2] * std::cos(t23) + a[3] * std::cos(t234));
  for (int k = 0; k < 3; ++k) CHECK(std::abs(translation_value(m, ws, 12 + k) - tip[k]) < 1e-15);
  // The paper's force vector F = [M1,0,0,M2,0,0,0,M3,0,0,0,M4,0,0,0,M4] puts the torques on
  // absolute angles: Q = TᵀF = (M1, M2 + M3 + 2 M4, M3 + 2 M4, 2 M4), not the joint torques.
  VecX F = VecX::Zero(16);
  const double M1 = 0.1, M2 = 0.2, M3 = 0.3, M4 = 0.4;
  F[0] = M1;
  F[3] = M2;
  F[7] = M3;
  F[11] = M4;
  F[15] = M4;
  VecX Q(4);
  Q << M1, M2 + M3 + 2 * M4, M3 + 2 * M4, 2 * M4;
  CHECK(rel_error(ws.T.transpose() * F, Q) < 1e-15);
}

TEST_CASE("finger with θ1 fixed: the flexion block is a planar 3-link arm", "[finger]") {
  const Model m = load_text(finger_json(""));
  Workspace ws(m);
  std::mt19937 rng(4);
  // Bar k (k = 1..3 for knuckles 2..4): mass ρ A l, inertia about the flexion axis through the
  // centroid ρ (A l³/12 + l I), I = w h³/12; joint angles from the palm normal.
  double mk[3], Ik[3], l[3];
  for (int k = 0; k < 3; ++k) {
    const double A = w[k + 1] * hh[k + 1];
    l[k] = a[k + 1];
    mk[k] = rho * A * l[k];
    Ik[k] = rho * (A * std::pow(l[k], 3) / 12 + l[k] * w[k + 1] * std::pow(hh[k + 1], 3) / 12);
  }
  for (int trial = 0; trial < 10; ++trial) {
    VecX q = random_uniform(4, 2.0, rng), qd = random_uniform(4, 3.0, rng);
    q[0] = 0;
    qd[0] = 0;
    evaluate(m, ws, q, qd, VecX());
    // Planar arm in (X, Z): centroid k = Σ_{j<k} l_j d(φ_j) + l_k/2 d(φ_k), d(φ) = (sin φ, cos φ)
    MatX M = MatX::Zero(3, 3);
    VecX h = VecX::Zero(3);
    double phi[3], phid[3];
    for (int k = 0; k < 3; ++k) {
      phi[k] = (k ? phi[k - 1] : 0) + q[k + 1];
      phid[k] = (k ? phid[k - 1] : 0) + qd[k + 1];
    }
    for (int k = 0; k < 3; ++k) {
      Eigen::Matrix<double, 2, 3> J = Eigen::Matrix<double, 2, 3>::Zero();
      Eigen::Vector2d bias = Eigen::Vector2d::Zero();
      for (int j = 0; j <= k; ++j) {
        const double len = j < k ? l[j] : l[k] / 2;
        // ∂/∂θ_i of len d(φ_j) = len d'(φ_j) for i ≤ j;  bias −len φ̇_j² d(φ_j)
        for (int i = 0; i <= j; ++i)
          J.col(i) += len * Eigen::Vector2d(std::cos(phi[j]), -std::sin(phi[j]));
        bias -= len * phid[j] * phid[j] * Eigen::Vector2d(std::sin(phi[j]), std::cos(phi[j]));
      }
      Eigen::RowVector3d ak = Eigen::RowVector3d::Zero();
      ak.head(k + 1).setOnes();
      M += mk[k] * J.transpose() * J + Ik[k] * ak.transpose() * ak;
      h += mk[k] * J.transpose() * bias;
    }
    CHECK(rel_error(ws.Ms.bottomRightCorner(3, 3), M) < 1e-13);
    CHECK(rel_error(ws.h.tail(3), h) < 1e-12);
  }
}

TEST_CASE("coupled finger: M^s, h, Q are the exact reduction Cᵀ(·)C of the free finger",
          "[finger]") {
  const Model free = load_text(finger_json(R"(, "stiffness": [0.1, 0.2, 0.3, 0.4],
      "rest": [0, 0.1, 0.2, 0.3], "damping": [0.01, 0.02, 0.03, 0.04])"));
  const Model coupled = load_text(finger_json(R"(, "stiffness": [0.1, 0.2, 0.3, 0.4],
      "rest": [0, 0.1, 0.2, 0.3], "damping": [0.01, 0.02, 0.03, 0.04],
      "coupling": {"ratio": 0.8, "offset": 0.05})"));
  REQUIRE(coupled.n() == 3);
  MatX C = MatX::Zero(4, 3);
  C(0, 0) = C(1, 1) = C(2, 2) = 1;
  C(3, 2) = 0.8;
  VecX theta0 = VecX::Zero(4);
  theta0[3] = 0.05;
  Workspace wf(free), wc(coupled);
  std::mt19937 rng(9);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(3, 1.5, rng), qd = random_uniform(3, 2, rng),
               tau = random_uniform(3, 0.1, rng);
    evaluate(coupled, wc, q, qd, tau);
    evaluate(free, wf, C * q + theta0, C * qd, VecX());
    CHECK(rel_error(wc.Ms, C.transpose() * wf.Ms * C) < 1e-13);
    CHECK(rel_error(wc.h, C.transpose() * wf.h) < 1e-12);
    CHECK(rel_error(wc.Q, C.transpose() * wf.Q + tau) < 1e-12);
  }
}
