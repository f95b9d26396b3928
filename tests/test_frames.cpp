// Frames and their kinematics (core/kinematics/frames.hpp) against finite differences of the poses:
// J's columns are the frame's velocity along each rate, J̇v the derivative of J v along v, in each
// of the three sets of axes; on trees of every joint type, a floating base, linear couplings and a
// coupling law (whose bias needs θ̈ = γ at q̈ = 0). And frames from JSON: xyz, node, rpy, errors.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "core/joints/rotation.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/sampling.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A free base, a ball, a universal, a planar joint, a revolute pair with a linear coupling and
// a slider, each body with an off-centre mass; named frames on two of them.
const char* kMixed = R"({"name": "mixed", "gravity": [0, 0, -9.81], "bodies": [
  {"name": "base", "parent": "world", "joint": {"type": "free"},
   "elements": [{"type": "rigid_body", "mass": 3, "com": [0.1, 0, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "ball", "parent": "base", "joint": {"type": "spherical", "origin": {"xyz": [0.2, 0.1, 0]}},
   "elements": [{"type": "rigid_body", "mass": 1, "com": [0.3, 0.1, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "cardan", "parent": "ball", "joint": {"type": "universal", "axis": [1, 0, 0],
     "axis2": [0, 0.6, 0.8], "origin": {"xyz": [0.3, 0, 0.1], "rpy": [0.2, 0, 0.1]}},
   "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.2, 0, 0.1], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "slab", "parent": "cardan", "joint": {"type": "planar", "axis": [0, 1, 1],
     "origin": {"xyz": [0.2, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.1, 0.1, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "j1", "parent": "slab", "joint": {"type": "revolute", "axis": [0, 0, 1],
     "origin": {"xyz": [0.2, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.3, "com": [0.2, 0, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "j2", "parent": "j1", "joint": {"type": "revolute", "axis": [0, 1, 0],
     "origin": {"xyz": [0.2, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.2, "com": [0.2, 0, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]},
  {"name": "tip", "parent": "j2", "joint": {"type": "prismatic", "axis": [1, 0, 0],
     "origin": {"xyz": [0.2, 0, 0]}},
   "elements": [{"type": "rigid_body", "mass": 0.1, "com": [0.05, 0, 0], "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.015}}]}],
 "couplings": [{"joint": "j2", "follows": "j1", "ratio": 0.7, "offset": 0.2}],
 "frames": [{"name": "tool", "body": "tip", "xyz": [0.1, -0.05, 0.02], "rpy": [0.3, -0.2, 0.5]},
            {"name": "wrist", "body": "ball", "xyz": [0, 0.1, 0.3]}]})";

// The frame's pose at q ⊕ t e (t = ±h), its velocity by central differences: the rotation from
// the difference of the two orientations, in world axes.
Vec6 velocity_fd(const Model& m, Workspace& ws, const VecX& q, const VecX& e, int f, double h) {
  FrameKinematics a, b;
  const VecX zero = VecX::Zero(m.n());
  frame_kinematics(m, ws, integrate_posture(m, q, h * e), zero, f, FrameAxes::LocalWorldAligned, a);
  frame_kinematics(m, ws, integrate_posture(m, q, -h * e), zero, f, FrameAxes::LocalWorldAligned,
                   b);
  const Eigen::AngleAxisd turn(a.R * b.R.transpose());
  Vec6 out;
  out << (a.p - b.p) / (2 * h), turn.axis() * turn.angle() / (2 * h);
  return out;
}

void check_model(const Model& m, unsigned seed) {
  Workspace ws(m);
  std::mt19937 rng(seed);
  const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
  const double h = 1e-6;
  for (int f = 0; f < static_cast<int>(m.frames.size()); ++f) {
    INFO("frame " << m.frames[f].name);
    FrameKinematics k;
    frame_kinematics(m, ws, q, v, f, FrameAxes::LocalWorldAligned, k);
    // J's columns: the frame's velocity along each rate.
    for (int c = 0; c < m.n(); ++c) {
      const Vec6 fd = velocity_fd(m, ws, q, VecX::Unit(m.n(), c), f, h);
      CHECK((k.J.col(c) - fd).norm() < 1e-7 * (1 + fd.norm()));
    }
    // In every set of axes: velocity = J v, and J̇v = d/dt (J v) along q ⊕ t v.
    for (FrameAxes axes : {FrameAxes::LocalWorldAligned, FrameAxes::Local, FrameAxes::World}) {
      INFO(frame_axes_name(axes));
      FrameKinematics here, ahead, behind;
      frame_kinematics(m, ws, q, v, f, axes, here);
      frame_kinematics(m, ws, integrate_posture(m, q, h * v), v, f, axes, ahead);
      frame_kinematics(m, ws, integrate_posture(m, q, -h * v), v, f, axes, behind);
      CHECK((here.velocity - here.J * v).norm() < 1e-12 * (1 + here.velocity.norm()));
      const Vec6 fd = (ahead.J * v - behind.J * v) / (2 * h);
      CHECK((here.bias - fd).norm() < 1e-6 * (1 + fd.norm()));
    }
  }
}

}  // namespace

TEST_CASE("frame Jacobians and J̇v equal finite differences in every set of axes", "[frames]") {
  SECTION("every joint type, a floating base, a linear coupling") {
    const Model m = load_text(kMixed);
    REQUIRE(m.frames.size() == m.bodies.size() + 2);
    check_model(m, 3);
  }
  SECTION("the four-bar finger: a coupling law (J̇v includes θ̈ = γ at q̈ = 0)") {
    const Model m = load_model(model_path("finger_fourbar.json"));
    REQUIRE(m.coupling_level);
    check_model(m, 4);
  }
  SECTION("the hand") { check_model(load_model(model_path("hand.json")), 5); }
}

TEST_CASE("a frame sits where its JSON puts it: xyz, rpy or a node of its body", "[frames]") {
  const Model m = load_text(kMixed);
  const int tool = find_frame(m, "tool"), tip = find_frame(m, "tip");
  REQUIRE(tool >= 0);
  REQUIRE(tip >= 0);
  Workspace ws(m);
  std::mt19937 rng(9);
  const VecX q = random_posture(m, rng), v = VecX::Zero(m.n());
  FrameKinematics a, b;
  frame_kinematics(m, ws, q, v, tool, FrameAxes::LocalWorldAligned, a);
  frame_kinematics(m, ws, q, v, tip, FrameAxes::LocalWorldAligned, b);
  CHECK((a.p - (b.p + b.R * Vec3(0.1, -0.05, 0.02))).norm() < 1e-14);
  CHECK((a.R - b.R * rpy_to_rotation(Vec3(0.3, -0.2, 0.5))).norm() < 1e-14);
  // A frame at a node: the finger's tip node.
  const Model finger = load_text(R"({"model": "dexterous_finger", "frames": [
      {"name": "fingertip", "body": "distal", "node": "b"}]})");
  CHECK(find_frame(finger, "tip") == static_cast<int>(finger.bodies.size()));  // the plugin's
  CHECK(find_frame(finger, "fingertip") == static_cast<int>(finger.bodies.size()) + 1);
  CHECK_THAT(text_error(R"({"model": "dexterous_finger", "frames": [
      {"name": "proximal", "body": "distal"}]})"),
             Catch::Contains("/name: frame name 'proximal' is taken"));
  CHECK_THAT(text_error(R"({"model": "dexterous_finger", "frames": [
      {"name": "x", "body": "nowhere"}]})"),
             Catch::Contains("/body: unknown body 'nowhere'"));
  CHECK_THAT(text_error(R"({"model": "dexterous_finger", "frames": [
      {"name": "x", "body": "distal", "node": "b", "xyz": [0, 0, 0]}]})"),
             Catch::Contains("give either xyz or node"));
}

TEST_CASE("info lists the frames, kinematics takes them by name", "[frames][cli]") {
  Scratch dir("frames_cli");
  std::ofstream(dir / "tip.json")
      << R"({"model": "dexterous_finger", "frames": [{"name": "fingertip", "body": "distal", "node": "b"}]})";
  const Run info = run("info " + (dir / "tip.json") + " --json");
  REQUIRE(info.code == 0);
  const auto j = nlohmann::json::parse(info.out);
  CHECK(j["frames"].back()["name"] == "fingertip");
  CHECK(j["frames"].back()["body"] == "distal");
  REQUIRE(j["frames"].size() == 6);  // base, proximal, middle, distal; the plugin's tip; fingertip
  CHECK(j["frames"][4]["name"] == "tip");  // the plugin's own, at the same node
  CHECK(j["frames"][4]["xyz"] == j["frames"][5]["xyz"]);
  const Run k = run("kinematics " + (dir / "tip.json") + " --frame fingertip,distal --json");
  REQUIRE(k.code == 0);
  CHECK(nlohmann::json::parse(k.out)["frames"].size() == 2);
  const Run bad = run("kinematics " + (dir / "tip.json") + " --frame nope");
  CHECK(bad.code == 2);
  CHECK_THAT(bad.out, Catch::Contains("--frame: no frame 'nope' (frames: base, proximal"));
}
