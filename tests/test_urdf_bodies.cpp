// URDF rigid bodies: links welded by fixed joints are checked as one body (merged as Pinocchio
// does), the balance-inertia repair against its definition, PyBullet's spherical joint, Drake's
// implied "world" parent, and what a file says that femdyn does not use.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/spatial/inertia.hpp"
#include "io/centroidal_mass.hpp"
#include "models/model_files.hpp"
#include "tests/helpers.hpp"
#include "tests/urdf_twin_checks.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Catch::Matchers::Contains;
using Catch::Matchers::Equals;

namespace {

std::string write_body_urdf(const std::string& name, const std::string& text) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("femdyn_urdf_bodies." + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

std::string number_text(double x) { return format_number(x, "%.17g"); }

std::string inertial_xml(double m, const Vec3& com, const Mat3& I) {
  return "<inertial><origin xyz=\"" + number_text(com.x()) + " " + number_text(com.y()) + " " +
         number_text(com.z()) + "\"/><mass value=\"" + number_text(m) + "\"/><inertia ixx=\"" +
         number_text(I(0, 0)) + "\" iyy=\"" + number_text(I(1, 1)) + "\" izz=\"" +
         number_text(I(2, 2)) + "\" ixy=\"" + number_text(I(0, 1)) + "\" ixz=\"" +
         number_text(I(0, 2)) + "\" iyz=\"" + number_text(I(1, 2)) + "\"/></inertial>";
}

// base -(revolute j1, z)- arm -(fixed, rotated and offset)- sensor, and arm -(revolute j2)- tip.
std::string welded_arm(const std::string& arm_inertial, const std::string& sensor_inertial) {
  return R"(<robot name="r"><link name="base"/><link name="arm">)" + arm_inertial +
         R"(</link><link name="sensor">)" + sensor_inertial + R"(</link><link name="tip">)" +
         inertial_xml(0.3, {0.05, 0, 0}, Vec3(1e-3, 2e-3, 2e-3).asDiagonal()) + R"(</link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="weld" type="fixed"><parent link="arm"/><child link="sensor"/>
    <origin xyz="0.02 0.01 0.3" rpy="0.4 -0.2 1.1"/></joint>
  <joint name="j2" type="revolute"><parent link="arm"/><child link="tip"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/></joint></robot>)";
}

Mat3 rotation_rpy(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Vec3::UnitZ()) * Eigen::AngleAxisd(p, Vec3::UnitY()) *
          Eigen::AngleAxisd(r, Vec3::UnitX()))
      .toRotationMatrix();
}

std::vector<std::string> warnings_of(const std::string& path, LoadOptions o = {}) {
  std::vector<std::string> w;
  o.warn = [&w](const std::string& text) { w.push_back(text); };
  (void)load_model(path, o);
  return w;
}

}  // namespace

TEST_CASE("a non-physical link welded to a body: the body is checked, with the merged mass",
          "[urdf][inertia]") {
  // The arm's own tensor violates the triangle inequality, the sensor's is rank one; welded
  // they are one physical body (the sensor 0.3 m above adds to the arm's x and y moments).
  // Reference: a file with that body's mass properties, merged here by hand (parallel axes), on the
  // arm and a massless sensor.
  const double m_a = 2, m_s = 0.5;
  const Vec3 c_a(0.01, 0, 0), c_s_local(0.02, 0, 0.01);
  const Mat3 I_a = Vec3(0.01, 0.02, 0.04).asDiagonal();  // 0.01 + 0.02 < 0.04
  const Mat3 I_s_local = Vec3(0, 0, 0.03).asDiagonal();  // rank one
  REQUIRE(inertia_problem(I_a));
  REQUIRE(inertia_problem(I_s_local));
  const Mat3 R = rotation_rpy(0.4, -0.2, 1.1);
  const Vec3 c_s = R * c_s_local + Vec3(0.02, 0.01, 0.3);
  const double m = m_a + m_s;
  const Vec3 c = (m_a * c_a + m_s * c_s) / m;
  const auto shift = [](double mass, const Vec3& d) {
    return Mat3(mass * (d.squaredNorm() * Mat3::Identity() - d * d.transpose()));
  };
  const Mat3 I = I_a + shift(m_a, c_a - c) + R * I_s_local * R.transpose() + shift(m_s, c_s - c);
  REQUIRE_FALSE(inertia_problem(I));

  const std::string split = write_body_urdf(
      "split.urdf",
      welded_arm(inertial_xml(m_a, c_a, I_a), inertial_xml(m_s, c_s_local, I_s_local)));
  const std::string merged = write_body_urdf("merged.urdf", welded_arm(inertial_xml(m, c, I), ""));
  const std::vector<std::string> notes = warnings_of(split);
  REQUIRE(notes.size() == 1);
  CHECK_THAT(notes[0], Contains("link 'arm', 'sensor': inertia violates the triangle inequality") &&
                           Contains("the rigid body of link 'arm'"));
  const Model a = load_model(split), b = load_model(merged);
  Workspace wa(a), wb(b);
  std::mt19937 rng(5);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(2, 3.0, rng), qd = random_uniform(2, 2.0, rng);
    evaluate(a, wa, q, qd, VecX());
    evaluate(b, wb, q, qd, VecX());
    CHECK(rel_error(wa.Ms, wb.Ms) < 1e-14);
    CHECK(rel_error(wa.h, wb.h) < 1e-14);
    CHECK(rel_error(wa.Q, wb.Q) < 1e-14);
  }
#ifdef FEMDYN_WITH_SIMBODY
  validation::UrdfTwin twin(split, a.gravity);  // Simbody, with the merge of its own
  check_equal_to_twin(
      a, twin, rng, [&] { return random_uniform(2, 3.0, rng); }, 1e-12);
#endif
}

TEST_CASE("a welded body still not physical is refused naming its head and links",
          "[urdf][inertia]") {
  const std::string path = write_body_urdf(
      "bad_body.urdf", welded_arm(inertial_xml(1, {0.1, 0, 0}, Vec3(0.01, 0.01, 0.05).asDiagonal()),
                                  inertial_xml(0.01, {0, 0, 0}, Vec3(0, 0, 1e-6).asDiagonal())));
  try {
    load_model(path);
    FAIL("loaded");
  } catch (const ModelError& e) {
    const std::string msg = e.what();
    CHECK_THAT(msg, Contains("bad_body.urdf: link 'arm' (a rigid body with the links welded to "
                             "it: 'sensor'): inertia violates the triangle inequality") &&
                        Contains("--balance-inertia"));
  }
  // With the repair, it loads and says what changed.
  const std::vector<std::string> notes = warnings_of(path, {.balance_inertia = true});
  CHECK_THAT(notes.back(), Contains("link 'arm' (a rigid body with the links welded to it: "
                                    "'sensor'): inertia balanced to the nearest physical one, "
                                    "principal moments "));
}

TEST_CASE("the links welded to a fixed base never move: their tensors are not checked",
          "[urdf][inertia]") {
  // A 1e-6 kg dummy root with a rank-one tensor (ANYmal, iCub), and a camera welded to it.
  const std::string dummy = inertial_xml(1e-6, Vec3::Zero(), Vec3(0, 0, 3e-6).asDiagonal());
  const std::string text =
      R"(<robot name="r"><link name="root">)" + dummy + R"(</link><link name="cam">)" + dummy +
      R"(</link><link name="base_inertia">)" +
      inertial_xml(10, {0, 0, 0.05}, Vec3(0.1, 0.2, 0.25).asDiagonal()) +
      R"(</link><link name="leg">)" +
      inertial_xml(1, {0, 0, -0.2}, Vec3(0.01, 0.01, 0.001).asDiagonal()) + R"(</link>
  <joint name="c" type="fixed"><parent link="root"/><child link="cam"/><origin xyz="0.3 0 0"/></joint>
  <joint name="b" type="fixed"><parent link="root"/><child link="base_inertia"/></joint>
  <joint name="hip" type="revolute"><parent link="root"/><child link="leg"/><axis xyz="1 0 0"/></joint>
  </robot>)";
  const std::string path = write_body_urdf("dummy_root.urdf", text);
  const std::vector<std::string> fixed_notes = warnings_of(path);
  REQUIRE(fixed_notes.size() == 1);
  CHECK_THAT(fixed_notes[0], Contains("link 'root', 'cam': inertia not physical, ignored: welded "
                                      "to the fixed base, it never moves"));
  // On a floating base the dummy root, the camera and the base's inertia are one body.
  const Model m = load_model(path, {.floating_base = true});
  CHECK(m.n() == 7);
  Workspace ws(m);
  mass_matrix(m, ws, neutral_posture(m));
  CHECK(ws.Ms(0, 0) == Approx(10 + 2e-6 + 1).epsilon(1e-12));  // total mass along vx
}

TEST_CASE("the nearest physical inertia: physical, nearest in second moments, equivariant",
          "[urdf][inertia]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto random_rotation = [&] {
    return Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  };
  const auto sigma = [](const Mat3& I) { return Mat3(0.5 * I.trace() * Mat3::Identity() - I); };
  for (int k = 0; k < 200; ++k) {
    const Mat3 R = random_rotation();
    const Vec3 p(std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng)));
    const Mat3 I = R * p.asDiagonal() * R.transpose();  // any p ≥ 0, often non-physical
    const Mat3 J = nearest_physical_inertia(I);
    CHECK_FALSE(inertia_problem(J));
    if (!inertia_problem(I)) CHECK((J - I).norm() < 1e-14);  // a physical I is kept
    // Equivariant: the repair does not depend on the axes the file uses.
    const Mat3 Q = random_rotation();
    CHECK((nearest_physical_inertia(Q * I * Q.transpose()) - Q * J * Q.transpose()).norm() < 1e-13);
    // Nearest in second moments: no physical tensor drawn near J is nearer to I.
    const double d = (sigma(J) - sigma(I)).norm();
    for (int t = 0; t < 20; ++t) {
      Mat3 S = sigma(J) + 0.05 * Mat3::NullaryExpr([&] { return u(rng); });
      S = 0.5 * (S + S.transpose());
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(S);
      S = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
          eig.eigenvectors().transpose();  // Σ ⪰ 0: a physical body
      CHECK((S - sigma(I)).norm() >= d - 1e-12);
    }
  }
  // A closed form: moments (0.001, 0.001, 0.01) of a thin disc drawn too flat. Σ's eigenvalues
  // are (0.005, 0.005, −0.004) -> (0.005, 0.005, 0): moments (0.005, 0.005, 0.01).
  const Mat3 J = nearest_physical_inertia(Vec3(0.001, 0.001, 0.01).asDiagonal());
  CHECK((J - Mat3(Vec3(0.005, 0.005, 0.01).asDiagonal())).norm() < 1e-17);
}

TEST_CASE("balance-inertia at every door: CLI, URDF reference, and refused on plain JSON",
          "[urdf][inertia]") {
  const std::string urdf = write_body_urdf(
      "flat.urdf", R"(<robot name="r"><link name="base"/><link name="disc">)" +
                       inertial_xml(1, {0.1, 0, 0}, Vec3(0.001, 0.001, 0.01).asDiagonal()) +
                       R"(</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="disc"/><axis xyz="0 0 1"/></joint></robot>)");
  const Run refused = run("info " + urdf);
  CHECK(refused.code == 1);
  CHECK_THAT(refused.out, Contains("flat.urdf: link 'disc': inertia violates the triangle "
                                   "inequality (principal moments 0.001, 0.001, 0.01); the "
                                   "balance_inertia option (--balance-inertia)"));
  const Run cli = run("equations " + urdf + " --balance-inertia --q 0 --qd 0");
  CHECK(cli.code == 0);
  CHECK_THAT(cli.out, Contains("link 'disc': inertia balanced to the nearest physical one, "
                               "principal moments 0.001, 0.001, 0.01 -> 0.005, 0.005, 0.01"));
  // M^s = I_zz + m r² with the balanced moment: 0.01 + 1 · 0.1².
  const Model m = load_model(urdf, {.balance_inertia = true});
  Workspace ws(m);
  mass_matrix(m, ws, VecX::Zero(1));
  CHECK(ws.Ms(0, 0) == Approx(0.01 + 0.01).epsilon(1e-14));
  const std::string ref = write_body_urdf(
      "ref.json", R"({"model": "urdf", "params": {"file": "flat.urdf", "balance_inertia": true}})");
  const Model r = load_model(ref);
  Workspace wr(r);
  mass_matrix(r, wr, VecX::Zero(1));
  CHECK(wr.Ms(0, 0) == ws.Ms(0, 0));
  const Run json =
      run("info " + std::string(FEMDYN_SOURCE_DIR) + "/models/pendulum.json --balance-inertia");
  CHECK(json.code == 1);
  CHECK_THAT(json.out, Contains("--balance-inertia is for URDF models"));
}

TEST_CASE("PyBullet's spherical joint and Drake's implied world parent", "[urdf][joints]") {
  const std::string text = R"(<robot name="r"><link name="torso">)" +
                           inertial_xml(5, {0, 0, 0.1}, Vec3(0.1, 0.12, 0.05).asDiagonal()) +
                           R"(</link><link name="head">)" +
                           inertial_xml(1, {0.02, 0, 0.1}, Vec3(0.01, 0.012, 0.008).asDiagonal()) +
                           R"(</link>
  <joint name="mount" type="fixed"><parent link="world"/><child link="torso"/><origin xyz="0 0 1"/></joint>
  <joint name="neck" type="spherical"><parent link="torso"/><child link="head"/>
    <origin xyz="0 0 0.3" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/><limit effort="10"/></joint></robot>)";
  const std::string path = write_body_urdf("ball.urdf", text);
  const std::vector<std::string> notes = warnings_of(path);
  CHECK(notes.size() == 2);  // <limit> and <axis> on the spherical joint
  const Model m = load_model(path);
  CHECK(m.n() == 3);
  CHECK(m.configuration_names.front() == "neck.qw");
#ifdef FEMDYN_WITH_SIMBODY
  validation::UrdfTwin twin(path, m.gravity);  // Simbody's Ball mobilizer
  std::mt19937 rng(3);
  check_equal_to_twin(
      m, twin, rng, [&] { return random_posture(m, rng); }, 1e-12);
#endif
}

TEST_CASE("what a URDF says that femdyn does not use is reported", "[urdf]") {
  const std::string body = inertial_xml(1, {0.1, 0, 0}, Vec3(0.01, 0.01, 0.01).asDiagonal());
  const std::string path =
      write_body_urdf("unused.urdf", R"(<robot name="r"><link name="base"/><link name="a">)" +
                                         body + R"(</link><link name="b">)" + body + R"(</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="w" type="fixed"><parent link="a"/><child link="b"/><mimic joint="j"/></joint></robot>)");
  const std::vector<std::string> notes = warnings_of(path);
  REQUIRE(notes.size() == 1);
  CHECK_THAT(notes[0], Contains("joint 'w': <mimic> ignored on a fixed joint"));
  // A file in which nothing moves says how to make it move.
  const std::string still = write_body_urdf(
      "still.urdf", R"(<robot name="drone"><link name="base_link">)" + body + "</link></robot>");
  const Run r = run("info " + still);
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Contains("still.urdf: root link 'base_link' is welded to the world and no "
                             "joint moves") &&
                        Contains("--floating-base"));
  CHECK(run("info " + still + " --floating-base").code == 0);
}

TEST_CASE("a massless chain end: info, import and view describe it, the dynamics refuse",
          "[urdf][cli]") {
  // ABB's and WidowX's files: a joint whose links carry no mass. M^s is singular; describing
  // the model needs no M^s, computing its motion does.
  const std::string heavy = inertial_xml(1, {0.1, 0, 0}, Vec3(0.01, 0.01, 0.01).asDiagonal());
  const std::string path = write_body_urdf(
      "massless_end.urdf", R"(<robot name="r"><link name="base"/><link name="arm">)" + heavy +
                               R"(</link><link name="finger"/>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="grip" type="revolute"><parent link="arm"/><child link="finger"/><axis xyz="1 0 0"/></joint></robot>)");
  const std::string note =
      "moving no inertia at all: 'grip': equations, simulate and the other "
      "dynamics commands refuse this model";
  const Run info = run("info " + path);
  CHECK(info.code == 0);
  CHECK_THAT(info.out, Contains("note: the mass matrix M^s is singular: coordinate 'grip' "
                                "moves no inertia") &&
                           Contains(note));
  const Run json = run("info " + path + " --json");
  CHECK(json.code == 0);
  CHECK_THAT(json.out, Contains("\"mass_matrix_singular\""));
  const Scratch scratch("massless_end");
  const std::string out = (scratch.dir / "end.json").string();
  const Run import = run("import " + path + " -o " + out);
  CHECK(import.code == 0);
  CHECK_THAT(import.out, Contains(note));
  CHECK(std::filesystem::exists(out));
  const Run view = run("view " + path + " --out " + (scratch.dir / "end.html").string());
  CHECK(view.code == 0);
  CHECK_THAT(view.out, Contains(note));
  for (const char* command : {"equations ", "simulate ", "validate "}) {
    const Run r = run(command + path);
    CHECK(r.code == 1);
    CHECK_THAT(r.out, Contains("massless_end.urdf: joint 'grip' (link 'finger'): the mass "
                               "matrix M^s is singular"));
  }
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("validate: a body Simbody cannot hold is not compared, exit 3, never FAIL or PASS",
          "[urdf][validation]") {
  // A massless link with a rotary inertia (Bolt's feet, PyBullet's panda_link8): femdyn reads a
  // rotary node; a Simbody body with no mass has no inertia.
  const std::string path = write_body_urdf(
      "rotor.urdf", R"(<robot name="r"><link name="base"/><link name="arm">)" +
                        inertial_xml(1, {0.1, 0, 0}, Vec3(0.01, 0.01, 0.01).asDiagonal()) +
                        R"(</link><link name="rotor">)" +
                        inertial_xml(0, Vec3::Zero(), Vec3(1e-4, 1e-4, 2e-4).asDiagonal()) +
                        R"(</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint>
  <joint name="spin" type="revolute"><parent link="arm"/><child link="rotor"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/></joint></robot>)");
  const Run r = run("validate " + path + " --states 2 --t-end 0");
  CHECK(r.code == 3);
  CHECK_THAT(r.out, Contains("body 'rotor' has a rotary inertia but no mass, which a Simbody "
                             "body cannot have") &&
                        Contains("NOT COMPARED"));
  const Run json = run("validate " + path + " --states 2 --t-end 0 --json");
  CHECK(json.code == 3);
  CHECK_THAT(json.out, Contains("\"compared\": false"));
}
#endif

TEST_CASE("the format is read from the content: a URDF named .xml, an MJCF file read as MJCF",
          "[urdf]") {
  const std::string body = inertial_xml(1, {0.1, 0, 0}, Vec3(0.01, 0.01, 0.01).asDiagonal());
  const std::string urdf = R"(<?xml version="1.0"?>
<!-- exported --><!-- twice -->
<robot name="r"><link name="base"/><link name="a">)" +
                           body + R"(</link>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint></robot>)";
  const Model by_content = load_model(write_body_urdf("robot.xml", urdf));
  const Model by_name = load_model(write_body_urdf("robot.urdf", urdf));
  CHECK(by_content.coordinate_names == by_name.coordinate_names);
  Workspace wa(by_content), wb(by_name);
  mass_matrix(by_content, wa, VecX::Constant(1, 0.3));
  mass_matrix(by_name, wb, VecX::Constant(1, 0.3));
  CHECK(wa.Ms == wb.Ms);
  const std::string mjcf = write_body_urdf("arm.xml", "<!-- a -->\n<mujoco model=\"m\"/>");
  const Run r = run("info " + mjcf);
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Contains("arm.xml: <worldbody> holds no body: nothing to compute"));
  // JSON under any name is still JSON.
  const std::string json = write_body_urdf(
      "pendulum.xml", R"({"name": "p", "bodies": [{"name": "b", "parent": "world", "joint": )"
                      R"({"type": "revolute", "axis": [0, 0, 1]}, "elements": [{"type": )"
                      R"("lumped_point", "node": [0.1, 0, 0], "mass": 1}]}]})");
  CHECK(load_model(json).n() == 1);
}

TEST_CASE("a DOF that barely moves is left out as a listed approximation, never silently",
          "[urdf]") {
  // rpy="3.141592654" is π + 3.5e-10: the axis tilts, the centre of mass rises and falls by
  // 6e-11 m per radian, below the 1e-10 L cut-off. femdyn leaves z out and says so.
  const auto robot = [](const std::string& roll) {
    return R"(<robot name="r"><link name="base"/><link name="a">)" +
           inertial_xml(1, {0.3, 0, 0}, Vec3(0.01, 0.01, 0.01).asDiagonal()) +
           R"(</link><joint name="j" type="revolute"><parent link="base"/><child link="a"/>)"
           R"(<origin rpy=")" +
           roll + R"( 0 0"/><axis xyz="0 0 1"/></joint></robot>)";
  };
  const Model tilted = load_model(write_body_urdf("tilted.urdf", robot("3.141592654")));
  REQUIRE(tilted.approximations.size() == 1);
  CHECK_THAT(tilted.approximations[0],
             Contains("a/com.z: moves by at most 6.") && Contains("treated as never moving"));
  const Model exact = load_model(write_body_urdf("exact.urdf", robot("3.141592653589793")));
  CHECK(exact.approximations.empty());
}

TEST_CASE("ANYmal B as published: a dummy root merged with its welded inertia, against Simbody",
          "[urdf][inertia]") {
  const std::string path =
      std::string(FEMDYN_SOURCE_DIR) + "/tests/data/urdf/example_robot_data_anymal_b.urdf";
  const std::vector<std::string> welded = warnings_of(path);
  CHECK_THAT(welded.front(), Contains("link 'base': inertia not physical, ignored: welded to the "
                                      "fixed base"));
  const Model floating = load_model(path, {.floating_base = true});
  CHECK(floating.n() == 18);
#ifdef FEMDYN_WITH_SIMBODY
  validation::UrdfTwin twin(path, floating.gravity, true);
  std::mt19937 rng(9);
  check_equal_to_twin(
      floating, twin, rng, [&] { return random_posture(floating, rng); }, 1e-12, 3);
#endif
}
