// The analytic derivatives of the constrained forward dynamics (core/derivatives/loops.hpp)
// against central differences of constrained_forward_dynamics along the tangent q ⊕ ε e_m (step
// 1e-6) and their Richardson extrapolation (steps 1e-3 and 5e-4), at Baumgarte's rate 0 and 20:
// random trees with every constraint form (ball, ball in a plane, point on line, point on plane,
// distance, gear; a weld on trees of every joint type), at assembled and at off-loop states; the
// bundled loop models; a planar loop closed by 3-D balls (redundant rows); ∂q̈/∂τ against the
// differences in τ; a dead point refused.
#include <catch2/catch.hpp>
#include <functional>
#include <random>

#include "core/derivatives/derivatives.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "tests/differences.hpp"
#include "tests/helpers.hpp"
#include "tests/loop_checks.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// The worst relative errors: along q, along v, of ∂q̈/∂τ.
struct LoopAgreement {
  double central = 0, richardson = 0, tau = 0;
  double central_v = 0, richardson_v = 0;
};

LoopAgreement compare(const Model& m, const VecX& q, const VecX& v, const VecX& tau, double omega) {
  Workspace ws(m), wf(m);
  LoopWorkspace lws(m), lf(m);
  DerivativeWorkspace d(m);
  const Function qdd_of = [&](const VecX& x, const VecX& y) {
    REQUIRE(constrained_forward_dynamics(m, wf, lf, x, y, tau, omega).ok);
    return VecX(wf.qdd);
  };
  REQUIRE(constrained_forward_dynamics_derivatives(m, ws, lws, d, q, v, tau, omega).ok);
  REQUIRE(constrained_forward_dynamics(m, wf, lf, q, v, tau, omega).ok);
  CHECK(rel_error(d.qdd, wf.qdd) < 1e-12);
  LoopAgreement a;
  for (const bool wrt_q : {true, false}) {
    const MatX& analytic = wrt_q ? d.dqdd_dq : d.dqdd_dv;
    const MatX c = central(m, qdd_of, q, v, wrt_q, 1e-6), r = richardson(m, qdd_of, q, v, wrt_q);
    // relative to the larger of the two derivatives (one of them may vanish)
    const double scale = std::max({r.cwiseAbs().maxCoeff(), d.dqdd_dq.cwiseAbs().maxCoeff(),
                                   d.dqdd_dv.cwiseAbs().maxCoeff()});
    (wrt_q ? a.central : a.central_v) = rel_error(analytic, c, scale);
    (wrt_q ? a.richardson : a.richardson_v) = rel_error(analytic, r, scale);
  }
  // ∂q̈/∂τ: q̈ is affine in τ, so one difference of step 1 per column is exact but for round-off.
  const int n = m.n();
  MatX fd(n, n);
  for (int k = 0; k < n; ++k) {
    REQUIRE(constrained_forward_dynamics(m, wf, lf, q, v, tau + VecX::Unit(n, k), omega).ok);
    fd.col(k) = wf.qdd;
    REQUIRE(constrained_forward_dynamics(m, wf, lf, q, v, tau - VecX::Unit(n, k), omega).ok);
    fd.col(k) = (fd.col(k) - wf.qdd) / 2;
  }
  // relative to the tree's (M^s)⁻¹ (a loop may lock the tree: ∂q̈/∂τ = 0 but for round-off)
  mass_matrix(m, wf, q);
  const MatX tree_inverse = wf.Ms.inverse();
  a.tau = rel_error(d.Minv, fd, tree_inverse.cwiseAbs().maxCoeff());
  return a;
}

void check(const Model& m, const VecX& q, const VecX& v, const VecX& tau, double omega,
           LoopAgreement& worst, double richardson_tolerance = 1e-9) {
  const LoopAgreement a = compare(m, q, v, tau, omega);
  CAPTURE(omega, a.central, a.richardson, a.central_v, a.richardson_v, a.tau);
  CHECK(std::max(a.central, a.central_v) < 1e-6);
  CHECK(std::max(a.richardson, a.richardson_v) < richardson_tolerance);
  CHECK(a.tau < 1e-10);
  worst.central = std::max({worst.central, a.central, a.central_v});
  worst.richardson = std::max({worst.richardson, a.richardson, a.richardson_v});
  worst.tau = std::max(worst.tau, a.tau);
}

// τ of a moderate q̈ of the tree (so that the constrained q̈ is moderate too).
VecX moderate_tau(const Model& m, const VecX& q, const VecX& v, std::mt19937& rng) {
  Workspace ws(m);
  inverse_dynamics(m, ws, q, v, random_uniform(m.n(), 2, rng));
  return ws.tau;
}

// A random tree of every joint type (universal, planar, spherical, free base on odd seeds) with a
// ball, a weld, a point on a plane and a distance between random places: off the loops.
std::string mixed_loop_tree(unsigned seed) {
  Json j = Json::parse(mixed_tree_json(seed, 8, 0.5, false, true));
  std::mt19937 rng(seed);
  const auto name = [&](int b) { return j["bodies"][b]["name"]; };
  j["constraints"] =
      Json::array({{{"type", "ball"}, {"a", place(name(7), rng)}, {"b", place(name(2), rng)}},
                   {{"type", "weld"}, {"a", place(name(5), rng)}, {"b", place(name(1), rng)}},
                   {{"type", "point_on_plane"},
                    {"a", place(name(6), rng)},
                    {"b", "world"},
                    {"normal", {0.2, -0.4, 1}}},
                   {{"type", "distance"},
                    {"a", place(name(4), rng)},
                    {"b", place(name(3), rng)},
                    {"length", 0.4}}});
  return j.dump();
}

}  // namespace

TEST_CASE("loop derivatives: every constraint form, off the loops", "[loop_derivatives]") {
  LoopAgreement worst;
  int states = 0;
  for (unsigned seed = 1; seed <= 8; ++seed)
    for (const double omega : {0.0, 20.0}) {
      INFO("every_constraint_tree " << seed);
      const Model m = load_text(every_constraint_tree(seed));
      std::mt19937 rng(seed);
      const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
      const VecX tau = moderate_tau(m, q, v, rng);
      Workspace ws(m);
      LoopWorkspace lws(m);
      // (a random posture far off the loops may be a dead point of the constraint rows)
      if (!constrained_forward_dynamics(m, ws, lws, q, v, tau, omega).ok) continue;
      // (far off the loops, near a dead point: the fourth derivatives the extrapolation leaves
      // are large; measured up to 3.5e-9)
      check(m, q, v, tau, omega, worst, 1e-8);
      ++states;
    }
  CHECK(states >= 8);
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    INFO("mixed_loop_tree " << seed);
    const Model m = load_text(mixed_loop_tree(seed));
    std::mt19937 rng(seed);
    const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
    check(m, q, v, moderate_tau(m, q, v, rng), 20.0, worst);
  }
  WARN("off the loops: central " << worst.central << ", Richardson " << worst.richardson << ", tau "
                                 << worst.tau);
}

TEST_CASE("loop derivatives: assembled closable trees with a weld or a ball",
          "[loop_derivatives]") {
  LoopAgreement worst;
  for (unsigned seed : {1u, 2u, 3u})
    for (const bool weld : {false, true}) {
      INFO("closable_tree " << seed << (weld ? " weld" : " ball"));
      const Model m = load_text(closable_tree(seed, weld));
      std::mt19937 rng(seed);
      VecX q = integrate_posture(m, neutral_posture(m), random_uniform(m.n(), 0.05, rng));
      VecX v = random_uniform(m.n(), 1.0, rng);
      REQUIRE(assemble_state(m, q, v).assembly.status.ok);
      const VecX tau = moderate_tau(m, q, v, rng);
      for (const double omega : {0.0, 20.0}) check(m, q, v, tau, omega, worst);
    }
  WARN("assembled: central " << worst.central << ", Richardson " << worst.richardson << ", tau "
                             << worst.tau);
}

TEST_CASE("loop derivatives: the bundled loop models", "[loop_derivatives]") {
  LoopAgreement worst;
  for (const char* file : {"andrews.json", "delta.json", "finger_fourbar_loop.json",
                           "five_bar.json", "iftomm_a02_nfourbar.json"}) {
    INFO(file);
    const Model m = load_model(model_path(file));
    std::mt19937 rng(7);
    VecX q = neutral_posture(m), v = random_uniform(m.n(), 1.0, rng);
    REQUIRE(assemble_state(m, q, v).assembly.status.ok);
    const VecX tau = moderate_tau(m, q, v, rng);
    // the N-four-bar: 40 balls on a plane, 80 of its 120 rows redundant
    const double richardson = std::string(file) == "iftomm_a02_nfourbar.json" ? 1e-8 : 1e-9;
    check(m, q, v, tau, 0.0, worst, richardson);
    check(m, q, v, tau, 20.0, worst, richardson);
    // off the loops
    const VecX off = integrate_posture(m, q, random_uniform(m.n(), 0.02, rng));
    LoopAgreement one;
    check(m, off, v, tau, 20.0, one, richardson);
    check(m, q, v, tau, 0.0, one, richardson);
    WARN(file << ": central " << one.central << ", Richardson " << one.richardson << ", tau "
              << one.tau);
  }
  WARN("bundled: central " << worst.central << ", Richardson " << worst.richardson << ", tau "
                           << worst.tau);
}

// Bricard's mechanism is mobile only where its loops hold: there Φ_q loses a rank it has just off
// them, so the constrained q̈ is not differentiable across the loops (a step off them changes
// the pivots kept) and only ∂q̈/∂v and ∂q̈/∂τ, at an assembled state, are compared.
TEST_CASE("loop derivatives: Bricard's mechanism along v and tau", "[loop_derivatives]") {
  const Model m = load_model(model_path("iftomm_a04_bricard.json"));
  std::mt19937 rng(7);
  VecX q = neutral_posture(m), v = random_uniform(m.n(), 1.0, rng);
  REQUIRE(assemble_state(m, q, v).assembly.status.ok);
  const VecX tau = moderate_tau(m, q, v, rng);
  for (const double omega : {0.0, 20.0}) {
    const LoopAgreement a = compare(m, q, v, tau, omega);
    CAPTURE(omega, a.central_v, a.richardson_v, a.tau);
    CHECK(a.central_v < 1e-6);
    CHECK(a.richardson_v < 1e-9);
    CHECK(a.tau < 1e-10);
    WARN("Bricard, omega " << omega << ": central " << a.central_v << ", Richardson "
                           << a.richardson_v << ", tau " << a.tau);
  }
}

TEST_CASE("loop derivatives: a planar loop closed by 3-D balls (redundant rows)",
          "[loop_derivatives]") {
  Json j = Json::parse(read_file(model_path("andrews.json")));
  for (Json& c : j["constraints"]) c.erase("normal");  // 3 equations each, the z rows repeat
  const Model m = load_text(j.dump());
  VecX q = neutral_posture(m);
  std::mt19937 rng(3);
  VecX v = random_uniform(m.n(), 20.0, rng);
  REQUIRE(assemble_state(m, q, v).assembly.status.ok);
  LoopAgreement worst;
  const VecX tau = moderate_tau(m, q, v, rng);
  for (const double omega : {0.0, 20.0}) check(m, q, v, tau, omega, worst);
  LoopWorkspace lws(m);
  Workspace ws(m);
  REQUIRE(constrained_forward_dynamics(m, ws, lws, q, v, tau, 0).ok);
  CHECK(lws.rank == 6);
  WARN("redundant: central " << worst.central << ", Richardson " << worst.richardson << ", tau "
                             << worst.tau);
}

TEST_CASE("loop derivatives: the dispatch, and a dead point is a failed Status",
          "[loop_derivatives]") {
  const Model m = load_model(model_path("five_bar.json"));
  std::mt19937 rng(5);
  VecX q = neutral_posture(m), v = random_uniform(m.n(), 1.0, rng);
  REQUIRE(assemble_state(m, q, v).assembly.status.ok);
  const VecX tau = moderate_tau(m, q, v, rng);
  REQUIRE(derivatives_unsupported(m).empty());
  Workspace ws(m), wl(m);
  LoopWorkspace lws(m);
  DerivativeWorkspace d(m), e(m);
  CHECK(d.baumgarte == kDefaultBaumgarte);
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, v, tau).ok);
  REQUIRE(constrained_forward_dynamics_derivatives(m, wl, lws, e, q, v, tau, kDefaultBaumgarte).ok);
  CHECK(d.dqdd_dq == e.dqdd_dq);
  CHECK(d.dqdd_dv == e.dqdd_dv);
  CHECK(d.Minv == e.Minv);
  // The projected inverse keeps q̈ on the loops: Φ_q ∂q̈/∂τ = 0.
  CHECK((lws.k.J * e.Minv).cwiseAbs().maxCoeff() < 1e-10 * e.Minv.cwiseAbs().maxCoeff());

  // Held still on the loops (τ = τ_ID(q, 0, 0): q̈ = 0, λ = 0), A has −ω twice for each of the
  // two independent rows (the directions off the loops), and at ω = 0 zeros there.
  const VecX still = VecX::Zero(m.n());
  inverse_dynamics(m, wl, q, still, still);
  const VecX hold = wl.tau;
  for (const double omega : {20.0, 0.0}) {
    d.baumgarte = omega;
    REQUIRE(forward_dynamics_derivatives(m, ws, d, q, still, hold).ok);
    CHECK(d.qdd.cwiseAbs().maxCoeff() < 1e-10);
    MatX A, B;
    linearization(m, d, still, A, B);
    const Eigen::VectorXcd eig = Eigen::EigenSolver<MatX>(A).eigenvalues();
    int at_omega = 0;
    for (const auto& z : eig) at_omega += std::abs(z + omega) < 1e-5 * (1 + omega);
    CHECK(at_omega == 4);
  }

  // The stretched loop (tests/loop_checks.hpp) is singular where it closes.
  const Model dead = load_text(stretched("2"));
  Workspace wd(dead);
  DerivativeWorkspace dd(dead);
  dd.baumgarte = 0;
  const Status st = forward_dynamics_derivatives(dead, wd, dd, VecX::Zero(2),
                                                 (VecX(2) << 2, -1).finished(), VecX::Zero(2));
  CHECK_FALSE(st.ok);
  CHECK(at_dead_point(st));
  CHECK(dd.dqdd_dq.allFinite());
}
