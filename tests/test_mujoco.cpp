// MuJoCo as a second peer (validation/mujoco_peer.hpp): femdyn's M^s, τ and q̈ on the iiwa,
// Atlas and HyQ, welded and floating, against MuJoCo's own URDF import; bad input in one line.
// Built only when CMake finds MuJoCo (FEMDYN_WITH_MUJOCO).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "io/urdf_loader.hpp"
#include "models/model_files.hpp"
#include "tests/helpers.hpp"
#include "validation/mujoco_peer.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string robot_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/" + name + ".urdf";
}

// The one-line message MujocoPeer throws on `path`, or "(loaded)".
std::string peer_error(const std::string& path, bool floating,
                       const std::vector<std::string>& names = {}) {
  try {
    validation::MujocoPeer peer(path, Vec3(0, 0, -9.81), floating, names);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(loaded)";
}

}  // namespace

TEST_CASE(
    "MuJoCo peer: M^s, inverse and forward dynamics of the iiwa, Atlas and HyQ, welded and "
    "floating, equal MuJoCo's",
    "[mujoco][validation]") {
  // (The iiwa's root link is "world": it has no floating base.)
  for (const auto& [robot, floating] : {std::pair{"iiwa", false},
                                        {"atlas", false},
                                        {"atlas", true},
                                        {"hyq", false},
                                        {"hyq", true}}) {
    INFO(robot << (floating ? ", floating base" : ", welded"));
    const std::string path = robot_path(robot);
    const Model m = load_model(path, {.floating_base = floating});
    validation::MujocoPeer peer(path, m.gravity, floating, m.coordinate_names);
    Workspace ws(m);
    std::mt19937 rng(7);
    double e_mass = 0, e_inverse = 0, e_forward = 0;
    for (int k = 0; k < 5; ++k) {
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
      const VecX qdd = random_uniform(m.n(), 5, rng), tau = random_uniform(m.n(), 1, rng);
      mass_matrix(m, ws, q);
      e_mass = std::max(e_mass, rel_error(ws.Ms, peer.mass(q)));
      inverse_dynamics(m, ws, q, qd, qdd);
      e_inverse = std::max(e_inverse, rel_error(ws.tau, peer.inverse(q, qd, qdd)));
      REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
      e_forward = std::max(e_forward, rel_error(ws.qdd, peer.forward(q, qd, tau)));
    }
    CHECK(e_mass < 1e-10);
    CHECK(e_inverse < 1e-10);
    CHECK(e_forward < 1e-10);
  }
}

TEST_CASE("MuJoCo peer: a URDF it cannot load or map is one line naming the file",
          "[mujoco][errors]") {
  Scratch scratch("mujoco_peer_errors");
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << text;
    return path;
  };
  const std::string junk = write("junk.urdf", "<robot name=\"r\"><link name=\"a\">");
  CHECK_THAT(peer_error(junk, false),
             Catch::StartsWith(junk + ": MuJoCo peer: malformed XML at line 1 ("));
  CHECK(peer_error(scratch / "none.urdf", false) ==
        scratch / "none.urdf" + ": MuJoCo peer: cannot open file");
  const std::string orphan = write("orphan.urdf", R"(<robot name="r"><link name="a"/>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <axis xyz="0 0 1"/></joint></robot>)");
  const std::string e = peer_error(orphan, false, {"j"});
  CHECK_THAT(e, Catch::StartsWith(orphan + ": MuJoCo: "));
  CHECK(e.find('\n') == std::string::npos);
  // hand16's <mimic> joints: 16 dofs in MuJoCo, 12 coordinates in femdyn.
  const std::string hand = model_path("urdf/hand16.urdf");
  CHECK_THAT(peer_error(hand, false, load_model(hand).coordinate_names),
             Catch::Contains("(a <mimic> joint?)"));
  CHECK_THAT(peer_error(robot_path("iiwa"), false, {"a", "b", "c", "d", "e", "f", "g"}),
             Catch::Contains("no hinge or slide joint named 'a'"));
}

TEST_CASE(
    "MuJoCo peer: a floating robot with a prismatic, a continuous and a fixed joint, tilted "
    "frames and full inertia tensors equals MuJoCo's",
    "[mujoco][validation]") {
  Scratch scratch("mujoco_peer_joints");
  const std::string path = scratch / "joints.urdf";
  const auto inertial = [](const char* rpy, const char* m, const char* tensor) {
    return std::string("<inertial><origin xyz=\"0.02 -0.03 0.05\" rpy=\"") + rpy +
           "\"/><mass value=\"" + m + "\"/><inertia " + tensor + "/></inertial>";
  };
  const char* full = R"(ixx="0.3" ixy="0.02" ixz="-0.04" iyy="0.25" iyz="0.01" izz="0.2")";
  std::ofstream(path) << "<robot name=\"r\"><link name=\"base\">" +
                             inertial("0.3 -0.7 1.1", "5", full) + "</link><link name=\"slider\">" +
                             inertial("0 0 0", "1.5", full) + "</link><link name=\"wheel\">" +
                             inertial("-1.2 0.4 2.0", "0.7", full) + "</link><link name=\"tool\">" +
                             inertial("0.1 0.2 0.3", "0.4", full) + "</link>" + R"(
      <joint name="slide" type="prismatic"><parent link="base"/><child link="slider"/>
        <origin xyz="0.1 0.2 -0.1" rpy="0.2 0.1 -0.3"/><axis xyz="0.6 0 0.8"/>
        <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
      <joint name="spin" type="continuous"><parent link="slider"/><child link="wheel"/>
        <origin xyz="0 0.3 0" rpy="1.0 0 0.5"/><axis xyz="0 1 0"/></joint>
      <joint name="weld" type="fixed"><parent link="wheel"/><child link="tool"/>
        <origin xyz="0.2 0 0.1" rpy="0 0.4 0"/></joint></robot>)";
  for (const bool floating : {false, true}) {
    INFO((floating ? "floating base" : "welded"));
    const Model m = load_model(path, {.floating_base = floating});
    validation::MujocoPeer peer(path, m.gravity, floating, m.coordinate_names);
    Workspace ws(m);
    std::mt19937 rng(3);
    for (int k = 0; k < 3; ++k) {
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
      const VecX qdd = random_uniform(m.n(), 5, rng), tau = random_uniform(m.n(), 1, rng);
      mass_matrix(m, ws, q);
      const double e_mass = rel_error(ws.Ms, peer.mass(q));
      inverse_dynamics(m, ws, q, qd, qdd);
      const double e_inverse = rel_error(ws.tau, peer.inverse(q, qd, qdd));
      REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
      const double e_forward = rel_error(ws.qdd, peer.forward(q, qd, tau));
      CHECK(e_mass < 1e-10);
      CHECK(e_inverse < 1e-10);
      CHECK(e_forward < 1e-10);
    }
  }
}

TEST_CASE("MuJoCo peer: the iiwa with rotors behind gears (dof_armature) equals femdyn's armature",
          "[mujoco][validation][actuators]") {
  // URDF has no armature: femdyn's document of the iiwa is given one per joint, and MuJoCo's
  // dof_armature the same I_a G², an independent implementation of the reflected inertia.
  const std::string path = robot_path("iiwa");
  Json doc = read_urdf(path).model;
  int k = 0;
  for (Json& b : doc["bodies"]) {
    if (b["joint"]["type"] == "fixed") continue;
    b["joint"]["armature"] = 1e-4 * (1 + k);
    b["joint"]["gear"] = 100 - 10 * k;
    ++k;
  }
  const Model m = load_text(doc.dump());
  REQUIRE(m.has_armature);
  VecX armature(m.n());
  for (int j = 0; j < m.n(); ++j) armature[j] = m.bodies[m.theta_joint[j]].joint.reflected_inertia;
  CHECK(armature.minCoeff() > 0.1);  // comparable with the links' own inertias
  validation::MujocoPeer peer(path, m.gravity, false, m.coordinate_names, armature);
  validation::MujocoPeer plain(path, m.gravity, false, m.coordinate_names);
  Workspace ws(m);
  std::mt19937 rng(3);
  for (int i = 0; i < 4; ++i) {
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
    const VecX qdd = random_uniform(m.n(), 5, rng), tau = random_uniform(m.n(), 1, rng);
    mass_matrix(m, ws, q);
    CHECK(rel_error(ws.Ms, peer.mass(q)) < 1e-10);
    CHECK(rel_error(ws.Ms, plain.mass(q)) > 1e-3);  // (the armature is not negligible)
    inverse_dynamics(m, ws, q, qd, qdd);
    CHECK(rel_error(ws.tau, peer.inverse(q, qd, qdd)) < 1e-10);
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    CHECK(rel_error(ws.qdd, peer.forward(q, qd, tau)) < 1e-10);
  }
}

TEST_CASE("bench compares like with like on a URDF with Coulomb friction (the gantry)",
          "[mujoco][bench]") {
#ifndef NDEBUG  // a Debug build (as the sanitizers'): bench refuses to time it
  return;
#endif
  // MuJoCo's frictionloss is a constraint, off in its smooth dynamics; bench hands femdyn's
  // regularised Coulomb force to MuJoCo as an applied force. Without it τ differed by 3.6 %.
  const Run r = run_shell(std::string(FEMDYN_BINARY) + " bench " + FEMDYN_SOURCE_DIR +
                          "/models/urdf/gantry.urdf --quick --states 2 2>&1 >/dev/null");
  CHECK(r.code == 0);
  CHECK(r.out.find("differ") == std::string::npos);
}
