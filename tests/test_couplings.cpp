// Nonlinear coupling laws θ_out = f(θ_in) (core/model/coupling_function.hpp) and the coupling level
// θ = g(q) they make (core/model/coupling_level.hpp, core/dynamics/coupling_chain.hpp).
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/model/coupling_function.hpp"
#include "core/model/errors.hpp"
#include "models/random_tree.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

struct Value {
  bool ok = false;
  double f = 0, df = 0, d2f = 0, d3f = 0;
};

Value at(const CouplingFunction& g, double x) {
  Value v;
  double df[1], d2f[1], d3f[1];
  v.ok = g.evaluate({&x, 1}, v.f, df, d2f);
  if (v.ok) g.third_derivatives({&x, 1}, d3f);
  v.df = df[0];
  v.d2f = d2f[0];
  v.d3f = d3f[0];
  return v;
}

// g', g'' and g''' against central differences of g, g' and g'' at x (step h).
void check_derivatives(const CouplingFunction& g, double x, double h = 1e-5) {
  const Value v = at(g, x), p = at(g, x + h), m = at(g, x - h);
  REQUIRE((v.ok && p.ok && m.ok));
  CHECK(std::abs(v.df - (p.f - m.f) / (2 * h)) <= 1e-8 * std::max(1.0, std::abs(v.df)));
  CHECK(std::abs(v.d2f - (p.df - m.df) / (2 * h)) <= 1e-7 * std::max(1.0, std::abs(v.d2f)));
  CHECK(std::abs(v.d3f - (p.d2f - m.d2f) / (2 * h)) <= 1e-7 * std::max(1.0, std::abs(v.d3f)));
}

FourBarCoupling::Geometry crank_rocker(int branch) {
  // Grashof: s + l = 1 + 3.5 ≤ p + q = 3 + 2, the shortest link is the crank: it turns fully.
  return {.ground = 3,
          .input = 1,
          .coupler = 3.5,
          .output = 2,
          .branch = branch,
          .input_offset = 0.4,
          .input_sign = -1,
          .output_offset = 1.2,
          .output_sign = 1};
}

}  // namespace

TEST_CASE("four-bar: g' and g'' match differences and the loop closes over a full turn",
          "[coupling]") {
  for (int branch : {1, -1}) {
    const FourBarCoupling g(crank_rocker(branch));
    CHECK_FALSE(g.lock_angle(-std::numbers::pi, std::numbers::pi));
    double worst = 0;
    for (int k = 0; k <= 400; ++k) {
      const double x = -std::numbers::pi + 2 * std::numbers::pi * k / 400;
      worst = std::max(worst, std::abs(g.closure_residual(x)));
      if (k % 20 == 0) check_derivatives(g, x);
    }
    CHECK(worst <= 1e-12);
  }
}

TEST_CASE("four-bar: a linkage that cannot turn fully locks where the closure has no solution",
          "[coupling]") {
  // Non-Grashof (s + l = 1 + 3 > p + q = 1.5 + 2): a triple rocker, it locks.
  const FourBarCoupling g({.ground = 3, .input = 2, .coupler = 1.5, .output = 1});
  REQUIRE(at(g, 0.0).ok);  // the crank tip 1 from the output pivot: assembles
  const auto lock = g.lock_angle(0.0, std::numbers::pi);
  REQUIRE(lock);
  // Up to the lock it assembles; just beyond, the loop would have to stretch (no ψ).
  CHECK(*lock > 0.1);
  CHECK(at(g, *lock - 1e-6).ok);
  CHECK_FALSE(at(g, *lock + 1e-6).ok);
  // Where it is stretched straight: |O + a e(φ) − P| = b + c.
  const double reach = std::hypot(2 * std::cos(*lock) - 3, 2 * std::sin(*lock));
  CHECK(reach == Approx(2.5).epsilon(1e-6));
}

TEST_CASE("polynomial and spline laws: derivatives, knots and continuity", "[coupling]") {
  const PolynomialCoupling p(2, {{0.3, {1, 0}}, {0.2, {1, 1}}, {-0.1, {0, 2}}, {0.05, {3, 0}}});
  const double x[2] = {0.7, -0.4};
  double f, df[2], d2f[4];
  REQUIRE(p.evaluate(x, f, df, d2f));
  CHECK(f == Approx(0.3 * 0.7 + 0.2 * 0.7 * -0.4 - 0.1 * 0.16 + 0.05 * 0.343).epsilon(1e-15));
  CHECK(df[0] == Approx(0.3 + 0.2 * -0.4 + 0.15 * 0.49).epsilon(1e-15));
  CHECK(df[1] == Approx(0.2 * 0.7 - 0.2 * -0.4).epsilon(1e-15));
  CHECK(d2f[0] == Approx(0.3 * 0.7).epsilon(1e-15));
  CHECK(d2f[1] == Approx(0.2).epsilon(1e-15));
  CHECK(d2f[2] == Approx(0.2).epsilon(1e-15));
  CHECK(d2f[3] == Approx(-0.2).epsilon(1e-15));
  // Third derivatives of 0.4 x0² x1 + 0.05 x0³: ∂³/∂x0³ = 0.3, ∂³/∂x0²∂x1 = 0.8 (in each
  // order), the rest 0; d3f[(k * 2 + l) * 2 + p].
  const PolynomialCoupling p3(2, {{0.4, {2, 1}}, {0.05, {3, 0}}});
  double d3f[8];
  p3.third_derivatives(x, d3f);
  const double expected[8] = {0.3, 0.8, 0.8, 0, 0.8, 0, 0, 0};
  for (int k = 0; k < 8; ++k) CHECK(d3f[k] == Approx(expected[k]).margin(1e-15));

  const std::vector<double> xs = {-3, -1, 0, 1, 3}, ys = {-1, 0.2, 0, 0.7, 1.2};
  const SplineCoupling s(xs, ys);
  for (std::size_t i = 0; i < xs.size(); ++i) CHECK(at(s, xs[i]).f == Approx(ys[i]).margin(1e-14));
  for (double x0 : {-2.5, -0.5, 0.3, 2.0, -4.0, 5.0}) check_derivatives(s, x0);
  // C² at the inner knots and natural ends (S'' = 0), continued straight beyond them.
  for (double k : {-1.0, 0.0, 1.0}) {
    const Value l = at(s, k - 1e-9), r = at(s, k + 1e-9);
    CHECK(std::abs(l.df - r.df) < 1e-7);
    CHECK(std::abs(l.d2f - r.d2f) < 1e-7);
  }
  CHECK(at(s, -3).d2f == Approx(0).margin(1e-12));
  CHECK(at(s, 3).d2f == Approx(0).margin(1e-12));
  CHECK(at(s, 4).df == Approx(at(s, 3).df).epsilon(1e-12));
}

TEST_CASE("a nonlinear law equal to a linear coupling gives the same equations", "[coupling]") {
  // A random tree with linear couplings (one of a coupled joint), and the same as polynomials.
  const Json params = {{"seed", 3}, {"bodies", 6}, {"branching", 0.3}, {"prismatic", true}};
  Json linear = random_tree(Params(params, "random_tree: "));
  linear["gravity"] = {0.3, -0.2, -9.81};
  linear["couplings"] = Json::parse(R"([
    {"joint": "j2", "follows": "j1", "ratio": 0.8, "offset": 0.1},
    {"joint": "j4", "follows": [{"joint": "j0", "ratio": 0.5}, {"joint": "j2", "ratio": -1}]}])");
  Json poly = linear;
  poly["couplings"][0] =
      Json::parse(R"({"joint": "j2", "follows": "j1", "polynomial": [[0.8, 1], [0.1, 0]]})");
  poly["couplings"][1] = Json::parse(
      R"({"joint": "j4", "follows": ["j0", "j2"], "polynomial": [[0.5, 1, 0], [-1, 0, 1]]})");
  const Model a = load_text(linear.dump()), b = load_text(poly.dump());
  REQUIRE_FALSE(a.coupling_level);
  REQUIRE(b.coupling_level);
  REQUIRE(a.n() == b.n());
  Workspace wa(a), wb(b);
  std::mt19937 rng(7);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(a.n(), 1.0, rng), qd = random_uniform(a.n(), 2.0, rng),
               tau = random_uniform(a.n(), 0.01, rng), qdd = random_uniform(a.n(), 50, rng);
    evaluate(a, wa, q, qd, tau);
    evaluate(b, wb, q, qd, tau);
    CHECK(rel_error(wb.Ms, wa.Ms) < 1e-14);
    CHECK(rel_error(wb.h, wa.h) < 1e-13);
    CHECK(rel_error(wb.Q, wa.Q) < 1e-13);
    REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
    REQUIRE(forward_dynamics(b, wb, q, qd, tau).ok);
    CHECK(rel_error(wb.qdd, wa.qdd) < 1e-12);
    inverse_dynamics(a, wa, q, qd, qdd);
    inverse_dynamics(b, wb, q, qd, qdd);
    CHECK(rel_error(wb.tau, wa.tau) < 1e-12);
    CHECK(energy(b, wb, q, qd).total() == Approx(energy(a, wa, q, qd).total()).epsilon(1e-13));
  }
}

TEST_CASE("nonlinear coupling: forward and inverse dynamics agree and M^s = Gᵀ M_θ G",
          "[coupling]") {
  const Model m = load_text(nonlinear_coupled_tree_json(8));
  Workspace ws(m);
  std::mt19937 rng(9);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(m.n(), 2.0, rng), qd = random_uniform(m.n(), 2.0, rng),
               tau = random_uniform(m.n(), 1.0, rng);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    const VecX qdd = ws.qdd;
    inverse_dynamics(m, ws, q, qd, qdd);
    CHECK(rel_error(ws.tau, tau) < 1e-10);
    // The kinetic energy of the tree at (θ, θ̇ = G q̇) is ½ q̇ᵀ M^s q̇.
    evaluate(m, ws, q, qd, tau);
    const double kinetic_q = 0.5 * qd.dot(ws.Ms * qd);
    CHECK(energy(m, ws, q, qd).kinetic == Approx(kinetic_q).epsilon(1e-12));
  }
}

TEST_CASE("a linkage that cannot assemble over its input's range is refused naming the angle",
          "[coupling]") {
  nlohmann::json doc = nlohmann::json::parse(nonlinear_coupled_tree_json(5));
  doc["couplings"][0]["four_bar"] = {{"ground", 3}, {"input", 2}, {"coupler", 1.5}, {"output", 1}};
  CHECK_THROWS_WITH(load_text(doc.dump()),
                    Catch::Contains("/couplings/0: the linkage of joint 'j2' cannot assemble or "
                                    "locks at j1 = ") &&
                        Catch::Contains("within a full turn [-3.14159, 3.14159] (give j1 limits)"));
  // Wrong arity and mixed forms are input errors naming the place.
  nlohmann::json bad = nlohmann::json::parse(nonlinear_coupled_tree_json(5));
  bad["couplings"][1]["polynomial"] = {{0.3, 1}};
  CHECK_THROWS_WITH(
      load_text(bad.dump()),
      Catch::Contains("/couplings/1/polynomial/0: expected [coefficient, 2 power(s)]"));
  bad = nlohmann::json::parse(nonlinear_coupled_tree_json(5));
  bad["couplings"][2]["ratio"] = 2;
  CHECK_THROWS_WITH(load_text(bad.dump()),
                    Catch::Contains("/couplings/2/ratio: belongs to a linear coupling"));
}

TEST_CASE("the four-bar finger runs in info, equations, simulate and check, and conserves energy",
          "[coupling][cli]") {
  const std::string model = model_path("finger_fourbar.json");
  const Run info = run("info " + model);
  REQUIRE(info.code == 0);
  CHECK_THAT(info.out, Catch::Contains("dip (revolute) middle -> distal   theta = four-bar (ground "
                                       "0.03, input 0.005, coupler 0.0285, output 0.007, branch "
                                       "1) of pip"));
  CHECK(run("equations " + model + " --q 0.1,0.5,1 --qd 0.5,1,1 --tensor").code == 0);
  CHECK(run("check " + model).code == 0);
  // A drift in the energy would show a wrong γ = g''[q̇, q̇] in h.
  const Run sim = run("simulate " + model +
                      " --q0 0,0.5,0.9 --qd0 0,0.5,0.5 --t-end 0.5 "
                      "--integrator dopri --rtol 1e-10 --atol 1e-12 --json");
  REQUIRE(sim.code == 0);
  const auto j = nlohmann::json::parse(sim.out);
  CHECK(j["ok"] == true);
  CHECK(j["energy_balance_relative"].get<double>() < 1e-9);
  // θ_dip = 0 at θ_pip = 0 by default (output_offset), and about (2/3) θ_pip over the range.
  const Model m = load_model(model);
  Workspace ws(m);
  for (double pip : {0.0, 0.5, 1.0, 1.75}) {
    mass_matrix(m, ws, (VecX(3) << 0, 0, pip).finished());
    CHECK(std::abs(ws.theta[3] - 2.0 / 3.0 * pip) < 0.02);
  }
  // Under gravity the finger falls past pip's limits (femdyn has no joint stops). With a 28 mm
  // coupler (a change-point linkage: 5 + 30 = 28 + 7) it reaches pip = −0.96, where the links
  // fall in line and the law is not defined: the run stops there with a one-line message. (The
  // bundled 28.5 mm linkage is defined over the full turn and falls on.)
  const std::string change_point =
      "/tmp/femdyn_fourbar_change_point_" + std::to_string(getpid()) + ".json";
  const Run fall = run_shell(
      "sed 's/\"coupler\": 0.0285/\"coupler\": 0.028/; "
      "s/\"input_offset\": 2.0264/\"input_offset\": 2.1816615649929116/' " +
      model + " > " + change_point + " && " + FEMDYN_BINARY + " simulate " + change_point +
      " --q0 0,0.5,0.9 --qd0 0,1,1 --t-end 0.5 --gravity 0,0,-9.81 --integrator dopri 2>&1; "
      "code=$?; rm -f " +
      change_point + "; exit $code");
  CHECK(fall.code != 0);
  CHECK_THAT(fall.out, Catch::Contains("/couplings/0: the law of joint 'dip' is not defined at "
                                       "pip = ") &&
                           !Catch::Contains("likely cause"));
  // The same linkage in every finger of the hand: 17 coordinates, energy conserved.
  const Run hand = run("simulate " + model_path("hand_fourbar.json") +
                       " --t-end 0.3 --integrator dopri --rtol 1e-10 --atol 1e-12 --qd0 "
                       "0.5,0.5,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1 --json");
  REQUIRE(hand.code == 0);
  const auto jh = nlohmann::json::parse(hand.out);
  CHECK(jh["n"] == 17);
  CHECK(jh["coordinates"].size() == 17);
  CHECK(jh["energy_balance_relative"].get<double>() < 1e-9);
  // validate builds the closed-loop twin (tests/test_validation.cpp checks its numbers).
  const Run v = run("validate " + model + " --states 3 --t-end 0.05");
  CHECK(v.code == 0);
  CHECK_THAT(v.out, Catch::Contains("loop ") && Catch::Contains("1 rod(s)"));
#ifdef NDEBUG  // (a build with asserts, tools/sanitize.sh: study refuses to time it)
  // study sweeps femdyn's and Simbody's integrators on the closed loop, and says that the two
  // do not integrate the same formulation (femdyn the reduced law, Simbody a constrained loop):
  // on the formulation line and in every ratio.
  const std::string out = "/tmp/femdyn_fourbar_study_" + std::to_string(getpid());
  const Run st = run_shell(std::string(FEMDYN_BINARY) + " study " + model + " --quick --out " +
                           out + " 2>&1; code=$?; rm -rf " + out + "; exit $code");
  CHECK(st.code == 0);
  CHECK_THAT(st.out, Catch::Contains("fastest Simbody") && !Catch::Contains("not built"));
  const std::string differ =
      "femdyn: reduced law; Simbody: constrained loop — not the same "
      "formulation";
  CHECK_THAT(st.out, Catch::Contains("formulation: " + differ));
  std::istringstream lines(st.out);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("| 1e-", 0) == 0 && line.find(" | —") == std::string::npos) {
      INFO(line);
      CHECK_THAT(line, Catch::EndsWith("(" + differ + ") |"));
    }
#endif
}

namespace {

// A planar four-bar as a tree: crank (j1) and rocker (j2) both hinged on the ground at
// O = 0 and P = (d, 0, 0), j2 = four_bar(j1); with `rod_mass` > 0 the coupler is a rod from
// the crank's tip to the rocker's tip (spanning the two bodies).
std::string four_bar_json(double coupler_in_law, double rod_mass) {
  Json doc = Json::parse(R"({"name": "four-bar", "gravity": [0, -9.81, 0], "bodies": [
    {"name": "crank", "parent": "world", "joint": {"name": "j1", "type": "revolute",
     "axis": [0, 0, 1]}, "nodes": {"tip": [0.1, 0, 0]},
     "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.2}]},
    {"name": "rocker", "parent": "world", "joint": {"name": "j2", "type": "revolute",
     "axis": [0, 0, 1], "origin": {"xyz": [0.3, 0, 0]}}, "nodes": {"tip": [0.2, 0, 0]},
     "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.3}]}]})");
  doc["couplings"] = Json::array({{{"joint", "j2"},
                                   {"follows", "j1"},
                                   {"four_bar",
                                    {{"ground", 0.3},
                                     {"input", 0.1},
                                     {"coupler", coupler_in_law},
                                     {"output", 0.2},
                                     {"output_offset", 0}}}}});
  if (rod_mass > 0)
    doc["bodies"][0]["elements"].push_back(
        {{"type", "rod"}, {"nodes", {"tip", "rocker/tip"}}, {"mass", rod_mass}});
  return doc.dump();
}

}  // namespace

TEST_CASE("a rod spanning two bodies: its length is kept and its M^s is (m/6)(2JaᵀJa + …)",
          "[coupling][elements]") {
  const Model bare = load_text(four_bar_json(0.35, 0)), with = load_text(four_bar_json(0.35, 0.4));
  REQUIRE(with.n() == 1);
  Workspace wb(bare), ww(with), wp(with), wm(with);
  const auto tips = [&](Workspace& ws, double q) {  // the rod's ends in world, from the poses
    mass_matrix(with, ws, VecX::Constant(1, q));
    const BodyState &c = ws.body[0], &r = ws.body[1];
    return std::pair<Vec3, Vec3>{ws.origin + c.p + c.R * Vec3(0.1, 0, 0),
                                 ws.origin + r.p + r.R * Vec3(0.2, 0, 0)};
  };
  for (double q : {-2.5, -1.0, 0.0, 0.7, 2.0}) {
    const auto [a, b] = tips(ww, q);
    CHECK((a - b).norm() == Approx(0.35).epsilon(1e-12));  // the loop closes at the rod
    // Independent: the rod's kinetic energy (m/6)(|v_a|² + v_a·v_b + |v_b|²) with the end
    // Jacobians by central differences of the end positions.
    const double h = 1e-6;
    const auto [ap, bp] = tips(wp, q + h);
    const auto [am, bm] = tips(wm, q - h);
    const Vec3 Ja = (ap - am) / (2 * h), Jb = (bp - bm) / (2 * h);
    const double rod = 0.4 / 3 * (Ja.dot(Ja) + Ja.dot(Jb) + Jb.dot(Jb));  // ½ M q̇² = T
    mass_matrix(bare, wb, VecX::Constant(1, q));
    mass_matrix(with, ww, VecX::Constant(1, q));
    CHECK(ww.Ms(0, 0) - wb.Ms(0, 0) == Approx(rod).epsilon(1e-8));
  }
  // Energy is conserved with the rod's gravity and velocity terms.
  const Run sim = run_shell("echo '" + four_bar_json(0.35, 0.4) + "' > /tmp/femdyn_fourbar_" +
                            std::to_string(getpid()) + ".json && " + FEMDYN_BINARY +
                            " simulate /tmp/femdyn_fourbar_" + std::to_string(getpid()) +
                            ".json --t-end 1 --qd0 3 --integrator dopri --rtol 1e-10 "
                            "--atol 1e-12 --json");
  REQUIRE(sim.code == 0);
  CHECK(Json::parse(sim.out)["energy_balance_relative"].get<double>() < 1e-9);
}

TEST_CASE("a spanning rod whose length the kinematics change is refused", "[coupling]") {
  // A rod to the rocker's middle instead of its tip: not a link of the loop.
  Json doc = Json::parse(four_bar_json(0.35, 0.4));
  doc["bodies"][1]["nodes"]["mid"] = {0.1, 0, 0};
  doc["bodies"][0]["elements"][1]["nodes"] = {"tip", "rocker/mid"};
  CHECK_THROWS_WITH(load_text(doc.dump()),
                    Catch::Contains("/bodies/0/elements/1: rod spanning two bodies does not keep "
                                    "its length: ") &&
                        Catch::Contains(" m at the reference posture, ") &&
                        Catch::Contains(" m at j1 = "));
}
