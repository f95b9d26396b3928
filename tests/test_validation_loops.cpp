// Loop constraints and two-point springs against Simbody (validation/validate_loops.hpp): random
// closed trees with every constraint type, and Andrews' squeezing mechanism. The constrained q̈
// and the generalized constraint forces Φ_qᵀλ at consistent states, and the closed mechanism's
// trajectory.
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <random>

#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "io/params.hpp"
#include "models/model_files.hpp"
#include "models/random_tree.hpp"
#include "tests/helpers.hpp"
#include "tests/validation_checks.hpp"
#include "validation/validate.hpp"
#include "validation/validate_loops.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Json = nlohmann::json;
using validation::ValidationReport;

namespace {

Json xyz(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

// rpy (x, then y, then z about fixed axes) of R.
Json rpy(const Mat3& R) { return xyz(R.eulerAngles(2, 1, 0).reverse()); }

// A random tree of `bodies` revolute and prismatic joints (one made spherical, with `ball`),
// closed at its neutral posture by constraints of the kinds in `kinds` between random bodies
// (or the world), each place chosen where the constraint holds, and a spring-damper.
std::string closed_tree(unsigned seed, int bodies, const std::vector<std::string>& kinds,
                        bool ball) {
  const Json params = {{"seed", seed}, {"bodies", bodies}, {"branching", 0.4}, {"prismatic", true}};
  Json j = random_tree(Params(params, "random_tree: "));  // the plugin's plain document
  j["gravity"] = {0.1, -0.2, -9.81};
  if (ball) {
    Json& joint = j["bodies"][bodies / 2]["joint"];
    joint["type"] = "spherical";
    joint.erase("axis");
  }
  const Model tree = load_text(j.dump());
  Workspace ws(tree);
  propagate(tree, ws, neutral_posture(tree), VecX::Zero(tree.n()),
            {.jacobian = false, .bias = false, .rows = false});
  std::mt19937 rng(seed * 7 + 1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> pick(0, bodies - 1);
  const auto vec = [&](double s) {  // (last to first, as GCC evaluated the constructor's
                                    // unsequenced arguments: the seeds keep their models)
    const double z = u(rng), y = u(rng), x = u(rng);
    return Vec3(s * x, s * y, s * z);
  };
  const auto pose = [&](int b, Mat3& R, Vec3& p) {
    R = b < 0 ? Mat3::Identity() : Mat3(ws.body[b].R);
    p = b < 0 ? Vec3::Zero() : Vec3(ws.origin + ws.body[b].p);
  };
  const auto name = [&](int b) { return b < 0 ? std::string("world") : tree.bodies[b].name; };
  Json constraints = Json::array();
  for (const std::string& kind : kinds) {
    Json c = {{"name", kind + std::to_string(constraints.size())}, {"type", kind}};
    if (kind == "gear") {
      int a = pick(rng), b = pick(rng);
      while (b == a || tree.bodies[a].joint.nq != 1 || tree.bodies[b].joint.nq != 1)
        a = pick(rng), b = pick(rng);
      c["joint"] = tree.bodies[a].joint.name;
      c["follows"] = tree.bodies[b].joint.name;
      c["ratio"] = 0.8 * u(rng);
      constraints.push_back(c);
      continue;
    }
    // A on a body, B on another or the world (every third constraint).
    const int a = pick(rng);
    int b = constraints.size() % 3 == 2 ? -1 : pick(rng);
    while (b == a) b = pick(rng);
    Mat3 Ra, Rb;
    Vec3 pa, pb;
    pose(a, Ra, pa), pose(b, Rb, pb);
    const Vec3 ra = vec(0.15), at = pa + Ra * ra;  // A's place in the world
    Vec3 place = at;                               // B's place in the world
    const Vec3 axis = vec(1).normalized();         // in B's axes
    if (kind == "point_on_line") place = at - 0.1 * (Rb * axis);
    if (kind == "point_on_plane") place = at - 0.1 * (Rb * axis).cross(vec(1)).normalized();
    if (kind == "distance") place = at + vec(0.2);
    c["a"] = {{"body", name(a)}, {"xyz", xyz(ra)}};
    c["b"] = {{"body", name(b)}, {"xyz", xyz(Rb.transpose() * (place - pb))}};
    if (kind == "weld") c["b"]["rpy"] = rpy(Rb.transpose() * Ra);  // A's axes (rpy 0) in B's
    if (kind == "ball" && constraints.size() % 2 == 1) c["normal"] = xyz(axis);
    if (kind == "point_on_plane") c["normal"] = xyz(axis);
    if (kind == "point_on_line") c["direction"] = xyz(axis);
    if (kind == "distance") c["length"] = (place - at).norm();
    constraints.push_back(c);
  }
  j["constraints"] = constraints;
  j["springs"] = Json::array({{{"a", {{"body", name(bodies - 1)}, {"xyz", xyz(vec(0.1))}}},
                               {"b", {{"body", "world"}, {"xyz", xyz(vec(0.3))}}},
                               {"stiffness", 30},
                               {"rest_length", 0.1},
                               {"damping", 0.4}},
                              {{"a", {{"body", name(1)}, {"xyz", xyz(vec(0.1))}}},
                               {"b", {{"body", name(bodies - 2)}, {"xyz", xyz(vec(0.1))}}},
                               {"stiffness", 12},
                               {"rest_length", 0.05}}});
  return j.dump();
}

const validation::QuantityError& row(const ValidationReport& r, const std::string& name) {
  for (const auto& q : r.quantities)
    if (q.name == name) return q;
  FAIL("no row " << name);
  throw;
}

}  // namespace

TEST_CASE("random closed trees with every constraint type and springs match Simbody",
          "[validation][loops]") {
  // Ball, ball in a plane (every other ball), weld, distance, point on line, point on plane and
  // gear, spread over trees of 10 to 14 bodies (one with a spherical joint every other seed).
  const std::vector<std::vector<std::string>> sets = {
      {"ball", "ball", "distance", "gear"},
      {"weld", "point_on_line", "point_on_plane", "gear"},
      {"point_on_line", "ball", "ball", "distance", "point_on_plane"},
      {"weld", "distance", "gear", "ball"}};
  double worst_qdd = 0, worst_force = 0, worst_closure = 0;
  int trajectories = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const auto& kinds = sets[seed % sets.size()];
    const int bodies = 10 + static_cast<int>(seed % 5);
    const Model m = load_text(closed_tree(seed, bodies, kinds, seed % 2 == 0));
    REQUIRE(m.constraints.size() == kinds.size());
    const ValidationReport r = validation::validate(m, quick(6, 0.05));
    INFO("seed " << seed << (r.failure.empty() ? "" : ": " + r.failure));
    REQUIRE(r.failure.empty());
    for (const auto& q : r.quantities) {
      INFO(q.name << ": " << q.max_rel << " > " << q.tolerance);
      CHECK(q.pass());
    }
    const auto &qdd = row(r, "constrained qdd"), &force = row(r, "constraint forces");
    CHECK(qdd.max_rel < 1e-10);
    CHECK(force.max_rel < 1e-10);
    CHECK(row(r, "closure").max_rel < 1e-10);
    CHECK(r.trajectory.constrained);
    // femdyn's RK4 stages leave the constraints, and where the random loops are (nearly)
    // redundant its constrained solve refuses them ("cannot be held"): those trajectories are
    // not compared. The others must match.
    INFO("trajectory: " << r.trajectory.skipped);
    if (r.trajectory.run) {
      ++trajectories;
      CHECK(r.trajectory.pass());
    } else {
      CHECK_THAT(r.trajectory.skipped, Catch::Contains("femdyn"));
    }
    worst_qdd = std::max(worst_qdd, qdd.max_rel);
    worst_force = std::max(worst_force, force.max_rel);
    worst_closure = std::max(worst_closure, row(r, "closure").max_rel);
  }
  CHECK(trajectories >= 3);  // measured: 3 of 8 (seeds 1 to 8)
  WARN("worst relative error: constrained qdd "
       << worst_qdd << ", constraint forces " << worst_force << ", closure " << worst_closure
       << "; " << trajectories << " of 8 trajectories compared");
}

TEST_CASE("a constraint femdyn gets wrong fails the constrained rows", "[validation][loops]") {
  // The twin from the model as built; femdyn's model with its line turned by 1 mrad: femdyn
  // assembles onto its own line, Simbody closes the other.
  const std::string text = closed_tree(3, 11, {"point_on_line", "gear"}, false);
  const Model m = load_text(text);
  validation::SimbodyTwin twin(validation::twin_model(m));
  REQUIRE(m.constraints[0].axes.size() == 2);
  const validation::ValidationOptions o = quick(4, 0);
  const double tol = validation::pointwise_tolerance(m);
  const validation::LoopRows right = validation::compare_loops(m, twin, o, tol);
  REQUIRE(right.failure.empty());
  CHECK(right.qdd.pass());
  CHECK(right.force.pass());
  Model wrong = load_text(text);
  const Mat3 turn = Eigen::AngleAxisd(1e-3, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  for (Vec3& e : wrong.constraints[0].axes) e = turn * e;
  const validation::LoopRows r = validation::compare_loops(wrong, twin, o, tol);
  REQUIRE(r.failure.empty());
  CHECK(r.closure.max_rel > 1e-6);
  CHECK_FALSE(r.qdd.pass());
  CHECK_FALSE(r.force.pass());
}

TEST_CASE("Andrews' squeezing mechanism matches Simbody, loops closed and open",
          "[validation][loops]") {
  const Model m = load_model(model_path("andrews.json"));
  const ValidationReport r = validation::validate(m, quick(10, 0.03));
  require_pass(r, "andrews.json");
  CHECK(row(r, "constrained qdd").max_rel < 1e-9);
  CHECK(row(r, "constraint forces").max_rel < 1e-9);
  CHECK(row(r, "Q").max_rel < 1e-10);  // the spring in the tree's Q
  CHECK(r.trajectory.constrained);
}

TEST_CASE("constrained dynamics: the articulated route equals M^s + Cholesky", "[loops][routes]") {
  // The articulated route forms neither M^s nor the body Jacobians (q̈₀ by the recursion, Φ_q by
  // the rates' spatial columns, Y = M⁻¹ Φ_qᵀ by its factorisation); the Cholesky route forms
  // both. Random closed trees with every constraint type, a spherical joint and springs, and
  // the bundled closed-loop models, at assembled random states.
  std::vector<std::pair<std::string, std::string>> texts;
  for (unsigned seed = 1; seed <= 6; ++seed)
    texts.emplace_back(
        "closed tree " + std::to_string(seed),
        closed_tree(seed, 9,
                    {"ball", "weld", "distance", "point_on_line", "point_on_plane", "gear"},
                    seed % 2 == 0));
  for (const char* name :
       {"andrews.json", "delta.json", "five_bar.json", "finger_fourbar_loop.json",
        "hand_fourbar_loop.json", "iftomm_a04_bricard.json"})
    texts.emplace_back(name, read_file(model_path(name)));
  for (const auto& [label, text] : texts) {
    INFO(label);
    const Model art = load_text(text);
    const Model chol = load_text(text, {.routes = {.dynamics = DynamicsRoute::Cholesky}});
    REQUIRE(art.dynamics_route == DynamicsRoute::Articulated);
    REQUIRE(chol.dynamics_route == DynamicsRoute::Cholesky);
    Workspace wa(art), wc(chol);
    LoopWorkspace la(art), lc(chol);
    std::mt19937 rng(11);
    for (int k = 0; k < 3; ++k) {
      VecX q = integrate_posture(art, neutral_posture(art), random_uniform(art.n(), 0.05, rng));
      VecX v = random_uniform(art.n(), 1, rng);
      const VecX tau = random_uniform(art.n(), 0.5, rng);
      REQUIRE(assemble_state(art, q, v).assembly.status.ok);
      const Status sa = constrained_forward_dynamics(art, wa, la, q, v, tau, 20);
      const Status sc = constrained_forward_dynamics(chol, wc, lc, q, v, tau, 20);
      INFO(sc.message << " / " << sa.message);
      REQUIRE(sc.ok);
      REQUIRE(sa.ok);
      CHECK(la.rank == lc.rank);
      CHECK(rel_error(la.k.J, lc.k.J) < 1e-13);
      CHECK(rel_error(la.k.bias, lc.k.bias, lc.k.J.cwiseAbs().maxCoeff() * v.squaredNorm()) <
            1e-12);
      CAPTURE(rel_error(wa.qdd, wc.qdd), la.rank);
      CHECK(rel_error(wa.qdd, wc.qdd) < 1e-9);
      const VecX fa = la.k.J.transpose() * la.lambda, fc = lc.k.J.transpose() * lc.lambda;
      CHECK(rel_error(fa, fc) < 1e-9);
    }
  }
}
