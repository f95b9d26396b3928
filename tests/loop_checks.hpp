// The equations a closed mechanism's q̈ and λ must satisfy at a consistent state (q, v):
// Φ_q v = 0 (the state is on the loops), Φ_q q̈ + Φ̇_q v = 0, and M q̈ + h = Q(τ) + Φ_qᵀ λ
// (inverse dynamics of q̈ gives back τ + Φ_qᵀ λ). Returns the constraints' rank at the solve.
// And the random closed trees the loop tests share (every_constraint_tree, closable_tree).
#pragma once
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "tests/helpers.hpp"

namespace femdyn::test {

using Json = nlohmann::json;

inline Json point(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  return Json::array({u(rng), u(rng), u(rng)});
}

inline Json place(const std::string& body, std::mt19937& rng) {
  return {{"body", body}, {"xyz", point(rng)}};
}

// A random tree of 9 bodies with one constraint of each kind except the weld (whose angle rows
// are a rotation vector, exact in its rate only where it holds), and a spring.
inline std::string every_constraint_tree(unsigned seed) {
  Json j = Json::parse(random_tree_json(seed, 9, 0.5, true));
  std::mt19937 rng(seed);
  j["constraints"] = Json::array(
      {{{"type", "ball"}, {"a", place("b8", rng)}, {"b", place("b3", rng)}},
       {{"type", "ball"}, {"a", place("b5", rng)}, {"b", "world"}, {"normal", {0.3, 0.2, 1}}},
       {{"type", "point_on_line"},
        {"a", place("b7", rng)},
        {"b", place("b1", rng)},
        {"direction", {1, 0.5, 0.2}}},
       {{"type", "point_on_plane"},
        {"a", place("b6", rng)},
        {"b", place("b2", rng)},
        {"normal", {0.1, 1, 0.4}}},
       {{"type", "distance"}, {"a", place("b4", rng)}, {"b", place("b0", rng)}, {"length", 0.3}},
       {{"type", "gear"}, {"joint", "j6"}, {"follows", "j2"}, {"ratio", 0.7}, {"offset", 0.1}}});
  j["springs"] = Json::array({{{"a", place("b8", rng)},
                               {"b", {{"body", "world"}, {"xyz", point(rng)}}},
                               {"stiffness", 40},
                               {"rest_length", 0.2},
                               {"damping", 0.5}}});
  return j.dump();
}

// A closable random tree: a 10-body tree whose last body is tied back to the world by a ball at
// its place in the neutral posture, a distance between two bodies at their neutral distance, a
// gear, and a spring. Loops that close at the neutral posture and keep some freedom.
inline std::string closable_tree(unsigned seed, bool weld) {
  Json j = Json::parse(random_tree_json(seed, 10, 0.3, false));
  Model tree = load_text(j.dump());
  Workspace ws(tree);
  const VecX q = neutral_posture(tree), v = VecX::Zero(tree.n());
  propagate(tree, ws, q, v, {.jacobian = false, .bias = false, .rows = false});
  std::mt19937 rng(seed);
  const int last = static_cast<int>(tree.bodies.size()) - 1;
  const Vec3 r = {0.05, 0.02, -0.03};
  const Vec3 p = ws.origin + ws.body[last].p + ws.body[last].R * r;  // (world)
  const Vec3 pa = ws.body[2].p, pb = ws.body[6].p;
  const std::string name_last = tree.bodies[last].name;
  j["constraints"] =
      Json::array({{{"name", "tip"},
                    {"type", weld ? "weld" : "ball"},
                    {"a", {{"body", name_last}, {"xyz", {r.x(), r.y(), r.z()}}}},
                    {"b", {{"body", "world"}, {"xyz", {p.x(), p.y(), p.z()}}, {"rpy", {0, 0, 0}}}}},
                   {{"name", "rod"},
                    {"type", "distance"},
                    {"a", tree.bodies[2].name},
                    {"b", tree.bodies[6].name},
                    {"length", (pa - pb).norm()}},
                   {{"name", "gear"},
                    {"type", "gear"},
                    {"joint", tree.bodies[4].joint.name},
                    {"follows", tree.bodies[1].joint.name},
                    {"ratio", -0.5}}});
  if (weld) {  // the weld's frame B: the last body's axes at the neutral posture
    const Mat3 R = ws.body[last].R;
    const Vec3 rpy = R.eulerAngles(2, 1, 0).reverse();
    j["constraints"][0]["b"]["rpy"] = {rpy.x(), rpy.y(), rpy.z()};
  }
  j["springs"] = Json::array({{{"a", place(tree.bodies[3].name, rng)},
                               {"b", {{"body", "world"}, {"xyz", point(rng)}}},
                               {"stiffness", 30},
                               {"rest_length", 0.1},
                               {"damping", 0.2}}});
  return j.dump();
}

inline int check_constrained_equations(const Model& m, const VecX& q, const VecX& v,
                                       const VecX& tau) {
  Workspace ws(m);
  LoopWorkspace lws(m);
  constraint_kinematics(m, ws, q, v, lws.k);
  CHECK((lws.k.J * v).cwiseAbs().maxCoeff() < 1e-12);
  REQUIRE(constrained_forward_dynamics(m, ws, lws, q, v, tau, 0).ok);
  const int rank = lws.rank;
  const VecX qdd = ws.qdd, lambda = lws.lambda;
  constraint_kinematics(m, ws, q, v, lws.k);
  const VecX accel = lws.k.J * qdd + lws.k.bias;
  CHECK(accel.cwiseAbs().maxCoeff() < 1e-9 * (1 + (lws.k.J * qdd).cwiseAbs().maxCoeff()));
  inverse_dynamics(m, ws, q, v, qdd);
  const VecX expected = tau + lws.k.J.transpose() * lambda;
  CHECK(rel_error(ws.tau, expected, 1e-6) < 1e-10);
  return rank;
}

// Two 1 m links from the origin, the tip held at (LENGTH, 0, 0): at 2 a loop that can only close
// fully stretched, where its Jacobian loses rank.
inline const char* kStretched = R"({"name": "stretched", "gravity": [0, -9.81, 0], "bodies": [
  {"name": "l1", "parent": "world", "joint": {"name": "a", "type": "revolute", "axis": [0, 0, 1]},
   "elements": [{"type": "rigid_body", "mass": 1, "com": [0.5, 0, 0],
                 "inertia": {"ixx": 0.01, "iyy": 0.1, "izz": 0.1}}]},
  {"name": "l2", "parent": "l1", "joint": {"name": "b", "type": "revolute", "axis": [0, 0, 1],
                                           "origin": {"xyz": [1, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 1, "com": [0.5, 0, 0],
                 "inertia": {"ixx": 0.01, "iyy": 0.1, "izz": 0.1}}]}],
  "constraints": [{"name": "tip", "type": "ball", "a": {"body": "l2", "xyz": [1, 0, 0]},
                   "b": {"body": "world", "xyz": [LENGTH, 0, 0]}, "normal": [0, 0, 1]}]})";

inline std::string stretched(const std::string& length) {
  std::string s = kStretched;
  return s.replace(s.find("LENGTH"), 6, length);
}

}  // namespace femdyn::test
