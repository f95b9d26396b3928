// Closed loops (core/loops/) and two-point springs (core/dynamics/springs.hpp): the constraint
// Jacobian and its bias against finite differences of Φ, the constrained q̈ and λ against the
// equations they must satisfy (Φ_q q̈ = −Φ̇_q v, and inverse dynamics giving back τ + Φ_qᵀλ),
// assembly and projection, redundancy and dead points, springs against their potential, and
// Andrews' squeezing mechanism against the Test Set for IVP Solvers (its consistent initial values
// at t = 0 and its reference solution at t = 0.03, computed there with PSIDE at tolerances 1e-14).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/dynamics/springs.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"
#include "tests/loop_checks.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;

namespace {

VecX phi_at(const Model& m, Workspace& ws, ConstraintKinematics& k, const VecX& q) {
  constraint_kinematics(m, ws, q, VecX::Zero(m.n()), k);
  return k.phi;
}

// The Test Set's Andrews mechanism (models/andrews.json), by coordinate name.
std::map<std::string, double> by_name(const Model& m, const VecX& x) {
  std::map<std::string, double> out;
  for (int i = 0; i < m.n(); ++i) out[m.coordinate_names[i]] = x[i];
  return out;
}

// Test Set parameters (andrews.f).
constexpr double rr = 7e-3, d = 28e-3, ss = 35e-3, sc = 18e-3, sd = 2e-2;
constexpr double xb = -0.03635, yb = .03273, xc = .014, yc = .072, c0 = 4530, l0 = 7785e-5;

}  // namespace

TEST_CASE("constraint Jacobians and biases agree with finite differences of Phi", "[loops]") {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Model m = load_text(every_constraint_tree(seed));
    REQUIRE(m.constraint_rows == 3 + 2 + 2 + 1 + 1 + 1);
    Workspace ws(m);
    ConstraintKinematics k(m);
    std::mt19937 rng(seed);
    const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
    constraint_kinematics(m, ws, q, v, k);
    const VecX rate = k.J * v, bias = k.bias;
    const double h = 1e-6, h2 = 1e-4;
    const VecX fd_rate = (phi_at(m, ws, k, q + h * v) - phi_at(m, ws, k, q - h * v)) / (2 * h);
    const VecX fd_bias =
        (phi_at(m, ws, k, q + h2 * v) - 2 * phi_at(m, ws, k, q) + phi_at(m, ws, k, q - h2 * v)) /
        (h2 * h2);
    CAPTURE(seed, rate.transpose(), fd_rate.transpose(), bias.transpose(), fd_bias.transpose());
    CHECK(rel_error(rate, fd_rate, 1e-3) < 1e-7);
    CHECK(rel_error(bias, fd_bias, 1e-1) < 1e-5);
  }
}

TEST_CASE("constrained dynamics satisfies the equations it solves", "[loops]") {
  for (bool weld : {false, true}) {
    for (unsigned seed : {4u, 5u}) {
      const Model m = load_text(closable_tree(seed, weld));
      CAPTURE(weld, seed);
      std::mt19937 rng(seed);
      // Assemble from a disturbed posture, then a random velocity projected onto the loops.
      VecX q = neutral_posture(m) + random_uniform(m.n(), 0.05, rng);
      VecX v = random_uniform(m.n(), 1.0, rng);
      const StateAssembly s = assemble_state(m, q, v);
      REQUIRE(s.assembly.status.ok);
      CHECK(s.assembly.residual < 1e-12);
      // (a weld on a body with fewer than 6 joints to the world repeats some of its rows)
      if (!weld) CHECK(s.assembly.redundant == 0);
      check_constrained_equations(m, q, v, random_uniform(m.n(), 0.5, rng));
    }
  }
}

TEST_CASE("two-point springs: force from the potential, damper power", "[loops]") {
  const Model m = load_text(every_constraint_tree(7));
  Workspace ws(m);
  std::mt19937 rng(7);
  const VecX q = random_posture(m, rng), v = VecX::Zero(m.n());
  spring_forces(m, ws, q, v);
  const VecX Q = ws.Q_springs;
  VecX fd(m.n());
  const double h = 1e-6;
  for (int i = 0; i < m.n(); ++i) {
    const VecX e = VecX::Unit(m.n(), i);
    fd[i] = -(spring_potential(m, ws, q + h * e) - spring_potential(m, ws, q - h * e)) / (2 * h);
  }
  CHECK(rel_error(Q, fd, 1e-6) < 1e-7);
  // The damper alone: Q_s(v) − Q_s(0) = −c l̇ ê pushed through J, its power −c l̇².
  const VecX w = random_uniform(m.n(), 1.0, rng);
  spring_forces(m, ws, q, w);
  const double power = (ws.Q_springs - Q).dot(w);
  CHECK(power < 0);
  CHECK(std::abs(power - ws.spring_power) < 1e-10 * std::abs(power));
}

TEST_CASE("Andrews' mechanism at t = 0 matches the Test Set's consistent values", "[loops]") {
  const Model m = load_model(model_path("andrews.json"));
  REQUIRE(m.n() == 7);
  REQUIRE(m.constraint_rows == 6);
  const VecX q = neutral_posture(m), v = VecX::Zero(7);
  const auto Q = by_name(m, q);
  CHECK(Q.at("beta") == -0.0617138900142764496358948458001);
  Workspace ws(m);
  LoopWorkspace lws(m);
  constraint_kinematics(m, ws, q, v, lws.k);
  CHECK(lws.k.phi.cwiseAbs().maxCoeff() < 1e-16);
  // The spring's force on γ, the Test Set's f3 (its closed form).
  spring_forces(m, ws, q, v);
  const double ga = Q.at("gamma");
  const double xd = sd * std::cos(ga) + sc * std::sin(ga) + xb;
  const double yd = sd * std::sin(ga) - sc * std::cos(ga) + yb;
  const double lang = std::hypot(xd - xc, yd - yc), force = -c0 * (lang - l0) / lang;
  const double f3 = force * (xd - xc) * (sc * std::cos(ga) - sd * std::sin(ga)) +
                    force * (yd - yc) * (sd * std::cos(ga) + sc * std::sin(ga));
  CHECK(std::abs(by_name(m, ws.Q_springs).at("gamma") - f3) < 1e-13 * std::abs(f3));
  // q̈ and the constraint forces: the Test Set's M q̈ = f − Gᵀλ is ours with Φ = g, λ = −λ_TS.
  REQUIRE(constrained_forward_dynamics(m, ws, lws, q, v, VecX::Zero(7), 0).ok);
  const auto qdd = by_name(m, ws.qdd);
  CHECK(std::abs(qdd.at("beta") - 14222.4439199541138705911625887) < 1e-9 * 14222.44);
  CHECK(std::abs(qdd.at("theta") - -10666.8329399655854029433719415) < 1e-9 * 14222.44);
  for (const char* zero : {"gamma", "phi", "delta", "omega", "epsilon"})
    CHECK(std::abs(qdd.at(zero)) < 1e-9 * 14222.44);
  const double l1 = 98.5668703962410896057654982170, l2 = -6.12268834425566265503114393122;
  const double be = Q.at("beta"), bt = be + Q.at("theta");
  const double G11 = -rr * std::sin(be) + d * std::sin(bt), G12 = d * std::sin(bt);
  const double G13 = -ss * std::cos(ga), G21 = rr * std::cos(be) - d * std::cos(bt);
  const double G22 = -d * std::cos(bt), G23 = -ss * std::sin(ga);
  const auto forces = by_name(m, lws.k.J.transpose() * lws.lambda);
  CHECK(std::abs(forces.at("beta") + (G11 * l1 + G21 * l2)) < 1e-9);
  CHECK(std::abs(forces.at("theta") + (G12 * l1 + G22 * l2)) < 1e-9);
  CHECK(std::abs(forces.at("gamma") + (G13 * l1 + G23 * l2)) < 1e-9);
  for (const char* zero : {"phi", "delta", "omega", "epsilon"})
    CHECK(std::abs(forces.at(zero)) < 1e-9);
}

TEST_CASE("Andrews' mechanism at t = 0.03 reproduces the Test Set's reference solution",
          "[loops]") {
  const Model m = load_model(model_path("andrews.json"));
  AdaptiveOptions o;
  o.rtol = 1e-12;
  o.atol = 1e-12;
  auto integ = make_integrator(m, {.kind = IntegratorKind::Dopri, .adaptive = o}, {});
  integ->reset(0, neutral_posture(m), VecX::Zero(7), 0.03);
  REQUIRE(integ->advance_to(0.03).ok);
  const auto q = by_name(m, integ->q()), v = by_name(m, integ->qd());
  // Test Set andsoln (PSIDE, rtol = atol = 1e-14).
  const std::map<std::string, std::pair<double, double>> reference = {
      {"beta", {0.1581077119629904e+2, 0.1139920302151208e+4}},
      {"theta", {-0.1575637105984298e+2, -0.1424379294994111e+4}},
      {"gamma", {0.4082224013073101e-1, 0.1103291221937134e+2}},
      {"phi", {-0.5347301163226948e+0, 0.1929337464421385e+2}},
      {"delta", {0.5244099658805304e+0, 0.5735699284790808e+0}},
      {"omega", {0.5347301163226948e+0, -0.1929337464421385e+2}},
      {"epsilon", {0.1048080741042263e+1, 0.3231791658026955e+0}}};
  for (const auto& [name, ref] : reference) {
    CAPTURE(name, q.at(name), ref.first, v.at(name), ref.second);
    CHECK(std::abs(q.at(name) - ref.first) < 1e-9 * (1 + std::abs(ref.first)));
    CHECK(std::abs(v.at(name) - ref.second) < 1e-6 * (1 + std::abs(ref.second)));
  }
}

TEST_CASE("a planar loop closed by 3-D balls is redundant, and moves the same", "[loops]") {
  const Model planar = load_model(model_path("andrews.json"));
  Json j = Json::parse(read_file(model_path("andrews.json")));
  for (Json& c : j["constraints"]) c.erase("normal");  // 3 equations each, the z rows repeat
  const Model spatial = load_text(j.dump());
  REQUIRE(spatial.constraint_rows == 9);
  VecX q = neutral_posture(spatial), v = VecX::Zero(7);
  const StateAssembly s = assemble_state(spatial, q, v);
  REQUIRE(s.assembly.status.ok);
  CHECK(s.assembly.rank == 6);
  CHECK(s.assembly.redundant == 3);
  std::mt19937 rng(3);
  v = random_uniform(7, 50.0, rng);
  REQUIRE(assemble_state(planar, q, v).assembly.status.ok);  // (v onto the loops)
  Workspace wa(planar), wb(spatial);
  LoopWorkspace la(planar), lb(spatial);
  REQUIRE(constrained_forward_dynamics(planar, wa, la, q, v, VecX::Zero(7), 0).ok);
  REQUIRE(constrained_forward_dynamics(spatial, wb, lb, q, v, VecX::Zero(7), 0).ok);
  CHECK(lb.rank == 6);
  CHECK(rel_error(wb.qdd, wa.qdd) < 1e-9);
  // The same constraint forces on the coordinates, whichever λ carries them.
  CHECK(rel_error(lb.k.J.transpose() * lb.lambda, la.k.J.transpose() * la.lambda) < 1e-9);
}

TEST_CASE("a dead point is a failure naming the constraint, not a NaN", "[loops]") {
  const Model m = load_text(stretched("2"));
  Workspace ws(m);
  LoopWorkspace lws(m);
  // Moving through the stretched configuration: v in the null space of Φ_q (the tip still).
  const VecX q = VecX::Zero(2);
  const VecX v = (VecX(2) << 2, -1).finished();
  const Status st = constrained_forward_dynamics(m, ws, lws, q, v, VecX::Zero(2), 0);
  CHECK_FALSE(st.ok);
  CHECK(st.message.find("singular") != std::string::npos);
  CHECK(st.message.find("'tip") != std::string::npos);
}

TEST_CASE("a loop that cannot close is refused with its residual", "[loops]") {
  const Model m = load_text(stretched("2.5"));
  VecX q = VecX::Zero(2), v = VecX::Zero(2);
  const StateAssembly s = assemble_state(m, q, v);
  CHECK_FALSE(s.assembly.status.ok);
  CHECK(s.assembly.status.message.find("cannot close") != std::string::npos);
  CHECK(s.assembly.status.message.find("'tip") != std::string::npos);
  CHECK(s.assembly.residual > 0.4);
  // Through the CLI: one line naming the file, non-zero exit.
  Scratch dir("stretched");
  const std::string path = (dir.dir / "stretched.json").string();
  std::ofstream(path) << stretched("2.5");
  const Run r = run("simulate " + path + " --t-end 0.1");
  CHECK(r.code != 0);
  CHECK(r.out.find("stretched.json: the initial state: the loops cannot close") !=
        std::string::npos);
}

TEST_CASE("assembly holds the given coordinates and lands on the loops", "[loops]") {
  const Model m = load_model(model_path("andrews.json"));
  const VecX q0 = neutral_posture(m);
  std::mt19937 rng(11);
  VecX q = q0 + random_uniform(7, 0.02, rng);
  Workspace ws(m);
  ConstraintKinematics k(m);
  AssemblyOptions o;
  o.held = {0};  // β, the crank: the driving coordinate stays where it is put
  const double beta = q[0];
  const AssemblyReport r = assemble(m, ws, k, q, o);
  REQUIRE(r.status.ok);
  CHECK(r.residual < 1e-12);
  CHECK(q[0] == beta);
  CHECK(r.iterations <= 8);  // Newton: quadratic from a few hundredths of a radian
}

TEST_CASE("constraint and spring input errors name the place and the problem", "[loops]") {
  const std::string base = R"({"name": "x", "bodies": [
    {"name": "a", "parent": "world", "joint": {"name": "ja", "type": "revolute", "axis": [0,0,1]},
     "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 1, "iyy": 1, "izz": 1}}]},
    {"name": "b", "parent": "a", "joint": {"name": "jb", "type": "revolute", "axis": [0,0,1]},
     "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 1, "iyy": 1, "izz": 1}}]}],
    EXTRA})";
  const auto with = [&](const std::string& extra) {
    std::string s = base;
    return text_error(s.replace(s.find("EXTRA"), 5, extra));
  };
  CHECK_THAT(with(R"("constraints": [{"type": "ball", "a": "nowhere", "b": "world"}])"),
             Catch::Contains("/constraints/0/a: unknown frame or body 'nowhere'"));
  CHECK_THAT(with(R"("constraints": [{"type": "hinge", "a": "a", "b": "world"}])"),
             Catch::Contains("/constraints/0/type: unknown constraint type 'hinge'"));
  CHECK_THAT(with(R"("constraints": [{"type": "ball", "a": "a", "b": {"body": "a"}}])"),
             Catch::Contains("/constraints/0: both ends are on body 'a'"));
  CHECK_THAT(with(R"("constraints": [{"type": "distance", "a": "a", "b": "b", "length": -1}])"),
             Catch::Contains("/constraints/0/length"));
  CHECK_THAT(with(R"("constraints": [{"type": "point_on_plane", "a": "a", "b": "b"}])"),
             Catch::Contains("/constraints/0: needs \"normal\""));
  CHECK_THAT(with(R"("constraints": [{"type": "ball", "a": "a", "b": "b", "normal": [0,0,0]}])"),
             Catch::Contains("/constraints/0/normal: must not be zero"));
  CHECK_THAT(with(R"("constraints": [{"type": "gear", "joint": "ja", "follows": "ja"}])"),
             Catch::Contains("a joint cannot follow itself"));
  CHECK_THAT(with(R"("constraints": [{"type": "gear", "joint": "jz", "follows": "ja"}])"),
             Catch::Contains("/constraints/0/joint: unknown joint 'jz'"));
  CHECK_THAT(with(R"("constraints": [{"type": "ball", "a": "a", "b": "b", "lenght": 1}])"),
             Catch::Contains("lenght"));
  CHECK_THAT(with(R"("springs": [{"a": "a", "b": "world", "stiffness": -3}])"),
             Catch::Contains("/springs/0/stiffness"));
  CHECK_THAT(
      with(R"("springs": [{"a": "a", "b": {"body": "a", "xyz": [1, 0, 0]}, "stiffness": 3}])"),
      Catch::Contains("/springs/0: both ends are on the same body"));
}
