// URDF import: closed forms for the conventions (inertial rpy, joint rpy, mimic, order),
// round trip through `femdyn import`, real robots and bundled URDFs, every bad-URDF class.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "io/urdf_loader.hpp"
#include "models/model_files.hpp"
#include "tests/helpers.hpp"
#include "tests/urdf_twin_checks.hpp"
#ifdef FEMDYN_WITH_SIMBODY
#include "validation/urdf_twin.hpp"
#include "validation/validate.hpp"
#endif

using namespace femdyn;
using namespace femdyn::test;
using Catch::Matchers::Equals;

namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  // One folder per process: ctest runs the test cases in parallel processes.
  const auto dir =
      std::filesystem::temp_directory_path() / ("femdyn_urdf_tests." + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

Model load_urdf_text(const std::string& text) { return load_model(write_temp("robot.urdf", text)); }

std::string error_of(const std::string& text) {
  const std::string path = write_temp("bad.urdf", text);
  try {
    load_model(path);
  } catch (const ModelError& e) {
    std::string msg = e.what();
    return msg.substr(msg.find("bad.urdf"));  // drop the temporary directory
  }
  return "(no error)";
}

std::string inertial(double m, const std::string& xyz, const std::string& rpy, double ixx,
                     double iyy, double izz) {
  return "<inertial><origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/><mass value=\"" +
         std::to_string(m) + "\"/><inertia ixx=\"" + std::to_string(ixx) + "\" iyy=\"" +
         std::to_string(iyy) + "\" izz=\"" + std::to_string(izz) +
         "\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
}

// A base and one link on a revolute joint; the pieces replaceable.
std::string one_link(const std::string& link_inertial, const std::string& joint_extra = "",
                     const std::string& axis = "1 0 0", const std::string& type = "revolute") {
  return R"(<robot name="r"><link name="base"/><link name="l">)" + link_inertial +
         R"(</link><joint name="j" type=")" + type + R"("><parent link="base"/><child link="l"/>
         <axis xyz=")" +
         axis + R"("/>)" + joint_extra + "</joint></robot>";
}

std::vector<std::string> urdf_files() {
  std::vector<std::string> out;
  for (const char* dir : {"/models/urdf", "/tests/robots"})
    for (const auto& e : std::filesystem::directory_iterator(std::string(FEMDYN_SOURCE_DIR) + dir))
      if (e.path().extension() == ".urdf") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("URDF <inertial> rpy rotates the inertia into the link frame", "[urdf]") {
  // Inertia (ixx, iyy, izz) = (1, 2, 3) turned by yaw π/2: about the link's x it is iyy = 2.
  const double pi = std::numbers::pi;
  for (const auto& [rpy, expected] :
       {std::pair{std::string("0 0 0"), 1.0}, std::pair{"0 0 " + std::to_string(pi / 2), 2.0},
        std::pair{"0 " + std::to_string(pi / 2) + " 0", 3.0}}) {
    INFO("inertial rpy " << rpy);
    const Model m = load_urdf_text(one_link(inertial(2.0, "0 0.1 0", rpy, 1, 2, 3)));
    Workspace ws(m);
    evaluate(m, ws, VecX::Zero(1), VecX::Zero(1), VecX::Zero(1));
    // M^s about x through the origin = I_xx(link) + m (0.1)².
    CHECK(ws.Ms(0, 0) == Approx(expected + 2.0 * 0.01).epsilon(1e-6));
  }
  // A general rpy, where R I Rᵀ and Rᵀ I R differ: about the joint axis x,
  // M^s = e_xᵀ (R I Rᵀ) e_x + m (0.1)², R = Rz(1.1) Ry(-0.4) Rx(0.3).
  const auto Rot = [](int axis, double a) { return Mat3(Eigen::AngleAxisd(a, Vec3::Unit(axis))); };
  const Mat3 R = Rot(2, 1.1) * Rot(1, -0.4) * Rot(0, 0.3);
  const Mat3 I = Vec3(1, 2, 3).asDiagonal();
  const double expected = (R * I * R.transpose())(0, 0) + 2.0 * 0.01;
  REQUIRE(std::abs((R.transpose() * I * R)(0, 0) + 2.0 * 0.01 - expected) >
          0.1);  // tells them apart
  const Model m = load_urdf_text(one_link(inertial(2.0, "0 0.1 0", "0.3 -0.4 1.1", 1, 2, 3)));
  Workspace ws(m);
  evaluate(m, ws, VecX::Zero(1), VecX::Zero(1), VecX::Zero(1));
  CHECK(ws.Ms(0, 0) == Approx(expected).epsilon(1e-12));
}

TEST_CASE("URDF joint origin rpy is R = Rz(yaw) Ry(pitch) Rx(roll), axis in the joint frame",
          "[urdf]") {
  // A point mass at the link origin's x = 0.5; joint at rpy (0.3, -0.4, 1.1) about axis z'.
  const Model m = load_urdf_text(
      R"(<robot name="r"><link name="base"/><link name="l">)" +
      inertial(1.5, "0.5 0 0", "0 0 0", 0, 0, 0) +
      R"(</link><joint name="j" type="revolute"><parent link="base"/><child link="l"/>
         <origin xyz="0.1 0.2 0.3" rpy="0.3 -0.4 1.1"/><axis xyz="0 0 2"/>
         <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>)");
  const auto R = [](int axis, double a) { return Mat3(Eigen::AngleAxisd(a, Vec3::Unit(axis))); };
  const Mat3 Rj = R(2, 1.1) * R(1, -0.4) * R(0, 0.3);
  const Vec3 w = Rj * Vec3::UnitZ();    // world axis of the joint (unit: axis normalised)
  const Vec3 r = Rj * Vec3(0.5, 0, 0);  // point from the joint at q = 0
  Workspace ws(m);
  const VecX q = VecX::Zero(1), qd = VecX::Constant(1, 2.0);
  evaluate(m, ws, q, qd, VecX::Zero(1));
  CHECK(ws.Ms(0, 0) == Approx(1.5 * w.cross(r).squaredNorm()).epsilon(1e-12));
  // Gravity torque about the axis: τ = w · (r × m g).
  CHECK(ws.Q[0] == Approx(w.dot(r.cross(1.5 * Vec3(0, 0, -9.81)))).epsilon(1e-12));
  CHECK(m.bodies[0].joint.lower == -1.0);
  CHECK(m.bodies[0].joint.upper == 1.0);
}

TEST_CASE("URDF mimic becomes θ = C q + θ0, coordinates in depth-first file order", "[urdf]") {
  const std::string urdf = R"(<robot name="tree">
    <link name="root"/>
    <link name="a">)" + inertial(1, "0.2 0 0", "0 0 0", 0.01, 0.01, 0.01) +
                           R"(</link>
    <link name="b">)" + inertial(1, "0.2 0 0", "0 0 0", 0.01, 0.01, 0.01) +
                           R"(</link>
    <link name="c">)" + inertial(1, "0.2 0 0", "0 0 0", 0.01, 0.01, 0.01) +
                           R"(</link>
    <link name="d">)" + inertial(1, "0.2 0 0", "0 0 0", 0.01, 0.01, 0.01) +
                           R"(</link>
    <joint name="j_d" type="revolute"><parent link="a"/><child link="d"/><axis xyz="0 1 0"/>
      <origin xyz="0.4 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
      <mimic joint="j_b" multiplier="-0.5" offset="0.1"/></joint>
    <joint name="j_c" type="continuous"><parent link="root"/><child link="c"/><axis xyz="0 0 1"/></joint>
    <joint name="j_a" type="continuous"><parent link="root"/><child link="a"/><axis xyz="0 0 1"/></joint>
    <joint name="j_b" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
      <limit lower="0" upper="0.2" effort="1" velocity="1"/></joint>
  </robot>)";
  const Model m = load_urdf_text(urdf);
  // Depth first from the root, children in the order their joints appear: root's children
  // are c (j_c) then a (j_a); a's are d (j_d, mimic) then b (j_b).
  REQUIRE(m.coordinate_names == std::vector<std::string>{"j_c", "j_a", "j_b"});
  REQUIRE(m.n_theta() == 4);
  for (int t = 0; t < 4; ++t) {
    const std::string& joint = m.bodies[m.theta_joint[t]].joint.name;
    INFO(joint);
    if (joint == "j_d") {
      CHECK(MatX(m.C).row(t).isApprox(Eigen::RowVector3d(0, 0, -0.5)));
      CHECK(m.theta0[t] == 0.1);
    } else {
      CHECK(m.theta0[t] == 0.0);
    }
  }
  CHECK(m.gravity.isApprox(Vec3(0, 0, -9.81)));  // URDF has none: femdyn's default
  LoadOptions o;
  o.gravity = Vec3(0, 0, 0);
  CHECK(load_model(write_temp("tree.urdf", urdf), o).gravity.isZero(0));
}

TEST_CASE("every URDF: import writes JSON that loads back to the same equations", "[urdf]") {
  for (const std::string& path : urdf_files()) {
    INFO(path);
    const Model direct = load_model(path);
    const Json doc = model_document(path);
    const Model back = load_model(write_temp("round_trip.json", doc.dump()));
    REQUIRE(back.n() == direct.n());
    CHECK(back.coordinate_names == direct.coordinate_names);
    Workspace wa(direct), wb(back);
    std::mt19937 rng(7);
    for (int k = 0; k < 3; ++k) {
      const VecX q = random_uniform(direct.n(), 1.0, rng),
                 qd = random_uniform(direct.n(), 2.0, rng),
                 tau = random_uniform(direct.n(), 1.0, rng);
      REQUIRE(forward_dynamics(direct, wa, q, qd, tau).ok);
      REQUIRE(forward_dynamics(back, wb, q, qd, tau).ok);
      evaluate(direct, wa, q, qd, tau);
      evaluate(back, wb, q, qd, tau);
      CHECK(rel_error(wb.Ms, wa.Ms) < 1e-12);
      CHECK(rel_error(wb.h, wa.h) < 1e-12);
      CHECK(rel_error(wb.Q, wa.Q) < 1e-12);
      CHECK(rel_error(wb.qdd, wa.qdd) < 1e-12);
    }
  }
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("every URDF (bundled and the real robots) matches Simbody", "[urdf][validation]") {
  for (const std::string& path : urdf_files()) {
    INFO(path);
    validation::ValidationOptions o;
    o.states = 6;
    o.t_end = 0.1;
    const validation::ValidationReport r = validation::validate(load_model(path), o);
    REQUIRE(r.failure.empty());
    for (const auto& q : r.quantities) {
      INFO(q.name);
      CHECK(q.max_rel < 1e-10);
    }
    CHECK(r.trajectory.run);
    CHECK(r.pass());
  }
}
#endif

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE(
    "the import itself: femdyn's equations of a URDF equal an independent Simbody model "
    "built from the XML",
    "[urdf][validation]") {
  // validation::UrdfTwin reads the XML on its own and uses Simbody's rpy sequence, inertia
  // re-expression and shift: a wrong convention in io/urdf_loader would show here (the twin of
  // `femdyn validate` is built from femdyn's model, so it cannot see import errors).
  for (const std::string& path : urdf_files()) {
    INFO(path);
    const Model m = load_model(path);
    validation::UrdfTwin twin(path, Vec3(0, 0, -9.81));
    std::mt19937 rng(21);
    check_equal_to_twin(m, twin, rng, [&] { return VecX(random_uniform(m.n(), 1.5, rng)); });
  }
}

// A robot with a planar joint (tilted normal, so e₁ is not the frame's x) and a floating joint
// inside the tree, tilted origins, full inertias and a mimic pair after them.
std::string inner_multi_dof_urdf() {
  const auto link = [](const std::string& name, double m) {
    return "<link name='" + name + "'><inertial><origin xyz='0.05 -0.02 0.1' rpy='0.3 0.1 -0.2'/>" +
           "<mass value='" + std::to_string(m) + "'/><inertia ixx='0.03' iyy='0.04' izz='0.05' " +
           "ixy='0.002' ixz='-0.001' iyz='0.003'/></inertial></link>";
  };
  const auto joint = [](const std::string& name, const std::string& type, const std::string& parent,
                        const std::string& child, const std::string& extra) {
    return "<joint name='" + name + "' type='" + type + "'><parent link='" + parent +
           "'/><child link='" + child + "'/><origin xyz='0.2 0.1 -0.3' rpy='0.2 -0.4 0.7'/>" +
           extra + "</joint>";
  };
  return "<robot name='inner'>" + link("base", 4) + link("l1", 2) + link("slab", 1.5) +
         link("puck", 1) + link("f1", 0.5) + link("f2", 0.4) +
         joint("j1", "revolute", "base", "l1", "<axis xyz='0 1 0'/>") +
         joint("glide", "planar", "l1", "slab", "<axis xyz='1 0.2 0.1'/>") +
         joint("drift", "floating", "slab", "puck", "") +
         joint("k1", "revolute", "puck", "f1", "<axis xyz='0 0 1'/>") +
         joint("k2", "revolute", "f1", "f2",
               "<axis xyz='0 0 1'/><mimic joint='k1' multiplier='0.7' offset='0.1'/>") +
         "</robot>";
}

TEST_CASE("a URDF by reference in JSON, welded or on a free root joint", "[urdf][joints]") {
  // {"model": "urdf", "params": {"file", "root_joint"}} loads the same equations as the URDF
  // itself (with --floating-base for "free"), the file's own name and gravity on top; errors
  // name the reference's place.
  const std::string hyq = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/hyq.urdf";
  for (const bool free : {false, true}) {
    const std::string ref = write_temp(
        "hyq_ref.json", R"({"model": "urdf", "name": "moon hyq", "gravity": [0, 0, -1.62],
          "params": {"file": ")" +
                            hyq + R"(", "root_joint": ")" + (free ? "free" : "fixed") + "\"}}");
    const Model a = load_model(ref);
    const Model b = load_model(hyq, {.gravity = Vec3(0, 0, -1.62), .floating_base = free});
    CHECK(a.name == "moon hyq");
    REQUIRE(a.n() == b.n());
    REQUIRE(a.n_q() == (free ? 19 : 12));
    Workspace wa(a), wb(b);
    std::mt19937 rng(5);
    const VecX q = random_posture(b, rng), qd = random_uniform(b.n(), 1.0, rng);
    evaluate(a, wa, q, qd, VecX());
    evaluate(b, wb, q, qd, VecX());
    CHECK(wa.Ms == wb.Ms);
    CHECK(wa.h == wb.h);
    CHECK(wa.Q == wb.Q);
  }
  const auto error_of = [](const std::string& text) {
    try {
      load_model(write_temp("bad_ref.json", text));
    } catch (const ModelError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  CHECK_THAT(error_of(R"({"model": "urdf", "params": {"file": "none.urdf"}})"),
             Catch::Contains("bad_ref.json: /params/file: ") &&
                 Catch::Contains("none.urdf: cannot open file"));
  CHECK_THAT(error_of(R"({"model": "urdf", "params": {"file": ")" + hyq +
                      R"(", "root_joint": "floating"}})"),
             Catch::Contains("/params/root_joint: expected \"fixed\" or \"free\""));
  CHECK_THAT(error_of(R"({"model": "urdf", "params": {"file": "a.json"}})"),
             Catch::Contains("/params/file: expected a *.urdf file"));
  CHECK_THAT(error_of(R"({"model": "urdf", "params": {"file": "a.urdf", "extra": 1}})"),
             Catch::Contains("/params/extra"));
}

TEST_CASE("inner planar and floating URDF joints: the import equals the independent twin",
          "[urdf][validation][joints]") {
  const std::string path = write_temp("inner_multi_dof.urdf", inner_multi_dof_urdf());
  for (const bool floating : {false, true}) {
    INFO("floating base " << floating);
    const Model m = load_model(path, {.floating_base = floating});
    REQUIRE(m.n() == (floating ? 6 : 0) + 1 + 3 + 6 + 1);
    validation::UrdfTwin twin(path, m.gravity, floating);
    std::mt19937 rng(23);
    check_equal_to_twin(m, twin, rng, [&] { return random_posture(m, rng); });
  }
  // femdyn validate checks the import too, and passes.
  const Run r = run("validate " + path + " --floating-base --states 3 --t-end 0.05");
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("import ") && Catch::EndsWith("PASS\n"));
}

TEST_CASE(
    "the import with a floating base: Atlas and HyQ equal an independent Simbody model whose "
    "root link is on a Free mobilizer",
    "[urdf][validation]") {
  // The twin's Free mobilizer has u = (ω, v) in the world, femdyn's free joint (v, ω) in the
  // base's axes: equal equations check that map, Ċ v in h included, as well as the import.
  for (const char* robot : {"atlas.urdf", "hyq.urdf"}) {
    INFO(robot);
    const std::string path = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/" + robot;
    const Model m = load_model(path, {.floating_base = true});
    validation::UrdfTwin twin(path, m.gravity, true);
    std::mt19937 rng(22);
    check_equal_to_twin(m, twin, rng, [&] { return random_posture(m, rng); });
    validation::ValidationOptions o;
    o.states = 4;
    std::string failure;
    CHECK(validation::validate_urdf_import(m, path, o, failure).max_rel < 1e-10);
    CHECK(failure.empty());
  }
}
#endif

TEST_CASE(
    "bundled URDFs: the arm has 7 DOF, the hand 16 joints and 12 coordinates, the "
    "gantry 3 prismatic axes",
    "[urdf]") {
  const Model arm = load_model(model_path("urdf/arm7.urdf"));
  CHECK(arm.n() == 7);
  const Model hand = load_model(model_path("urdf/hand16.urdf"));
  CHECK(hand.n_theta() == 16);
  CHECK(hand.n() == 12);
  const Model gantry = load_model(model_path("urdf/gantry.urdf"));
  int prismatic = 0;
  for (const Body& b : gantry.bodies) prismatic += b.joint.type == JointType::Prismatic;
  CHECK(prismatic == 3);
  // The rails' <dynamics friction> is Coulomb friction now, and <limit effort velocity> read:
  // nothing is ignored, so nothing is warned of.
  CHECK(read_urdf(model_path("urdf/gantry.urdf")).warnings.empty());
  const Joint& rail = gantry.bodies[0].joint;
  CHECK(rail.friction == 5);
  CHECK(rail.damping == 40);
  CHECK(rail.effort_limit == 2000);
  CHECK(rail.velocity_limit == 1.0);
  CHECK(gantry.has_effort_limits);
}

TEST_CASE("URDF <limit effort=\"0\"> is read as no limit, with a warning, negatives refused",
          "[urdf][actuators]") {
  const auto robot = [](const std::string& limit, const std::string& dynamics) {
    return R"(<robot name="r"><link name="base"/><link name="l">)" +
           inertial(1, "0.1 0 0", "0 0 0", 0.01, 0.01, 0.01) +
           R"(</link><joint name="j" type="revolute"><parent link="base"/><child link="l"/>
           <axis xyz="0 0 1"/>)" +
           limit + dynamics + "</joint></robot>";
  };
  const UrdfResult r =
      urdf_to_model(robot(R"(<limit lower="-1" upper="1" effort="0" velocity="2"/>)",
                          R"(<dynamics friction="0.4"/>)"),
                    "r.urdf");
  REQUIRE(r.warnings.size() == 1);
  CHECK_THAT(r.warnings[0], Catch::Contains("joint 'j'") && Catch::Contains("effort"));
  const Json& j = r.model["bodies"][0]["joint"];
  CHECK(!j.contains("effort_limit"));
  CHECK(j["velocity_limit"] == 2.0);
  CHECK(j["friction"] == 0.4);
  CHECK_THAT(error_of(robot(R"(<limit lower="-1" upper="1" effort="-3" velocity="2"/>)", "")),
             Equals("bad.urdf: joint 'j': negative limit effort"));
  CHECK_THAT(error_of(robot("", R"(<dynamics friction="-1"/>)")),
             Equals("bad.urdf: joint 'j': negative friction"));
}

TEST_CASE("bad URDF: one line naming the file, the link or joint, and the problem", "[urdf]") {
  const std::string ok_inertial = inertial(1, "0.1 0 0", "0 0 0", 0.01, 0.01, 0.01);
  CHECK(error_of(one_link(ok_inertial)) == "(no error)");
  CHECK_THAT(error_of("<robot name=\"r\"><link name=\"a\"></robot>"),
             Catch::StartsWith("bad.urdf: malformed XML at line 1"));
  CHECK_THAT(error_of(R"(<robot name="r"><link name="base"/><link name="l"/>
      <joint name="j" type="revolute"><parent link="nowhere"/><child link="l"/></joint></robot>)"),
             Equals("bad.urdf: joint 'j': parent link 'nowhere' does not exist"));
  CHECK_THAT(error_of(R"(<robot name="r"><link name="base"/>
      <joint name="j" type="revolute"><parent link="base"/><child link="l"/></joint></robot>)"),
             Equals("bad.urdf: joint 'j': child link 'l' does not exist"));
  CHECK_THAT(error_of(R"(<robot name="r"><link name="a"/><link name="b"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint></robot>)"),
             Equals("bad.urdf: no root link (the joints form a loop)"));
  CHECK_THAT(error_of(R"(<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>
      <joint name="j2" type="revolute"><parent link="a"/><child link="b"/></joint></robot>)"),
             Equals("bad.urdf: joint 'j2': link 'b' is already the child of joint 'j1' (a loop: "
                    "URDF describes trees)"));
  CHECK_THAT(error_of(R"(<robot name="r"><link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint></robot>)"),
             Equals("bad.urdf: more than one root link: 'a', 'c'"));
  CHECK_THAT(error_of(one_link(inertial(-1, "0 0 0", "0 0 0", 0.01, 0.01, 0.01))),
             Equals("bad.urdf: link 'l': negative mass -1"));
  CHECK_THAT(error_of(one_link(inertial(1, "0 0 0", "0 0 0", 0.01, 0.01, 0.05))),
             Equals("bad.urdf: link 'l': inertia violates the triangle inequality (principal "
                    "moments 0.01, 0.01, 0.05); the balance_inertia option (--balance-inertia) "
                    "takes the nearest physical inertia instead"));
  CHECK_THAT(
      error_of(one_link(
          "<inertial><mass value=\"nan\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial>")),
      Equals("bad.urdf: link 'l': value is NaN or Inf"));
  CHECK_THAT(error_of(one_link(ok_inertial, "", "0 0 0")),
             Equals("bad.urdf: joint 'j': axis is zero"));
  CHECK_THAT(error_of(one_link(ok_inertial, "", "0 0 0", "planar")),
             Equals("bad.urdf: joint 'j': axis is zero"));
  CHECK_THAT(error_of(one_link(ok_inertial, "", "1 0 0", "hinge")),
             Equals("bad.urdf: joint 'j': unknown type 'hinge'"));
  CHECK_THAT(
      error_of(
          R"(<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:macro name="m"/></robot>)"),
      Equals("bad.urdf: <xacro:macro> at line 1 is a xacro element: the file needs xacro, which "
             "femdyn does not run; expand it first (xacro robot.urdf.xacro > robot.urdf)"));
  CHECK_THAT(error_of(one_link(ok_inertial, "<mimic joint=\"ghost\"/>")),
             Equals("bad.urdf: joint 'j': mimics unknown joint 'ghost'"));
  // A movable massless leaf: M^s singular, named by the URDF joint and link, not a JSON path.
  CHECK_THAT(error_of(one_link("")), Catch::StartsWith("bad.urdf: joint 'j' (link 'l'): "));
}

TEST_CASE("a mimic of a fixed joint is named by the URDF joint", "[urdf]") {
  const std::string urdf = R"(<robot name="r"><link name="base"/><link name="a">)" +
                           inertial(1, "0.1 0 0", "0 0 0", 0.01, 0.01, 0.01) + R"(</link>
    <link name="b">)" + inertial(1, "0.1 0 0", "0 0 0", 0.01, 0.01, 0.01) +
                           R"(</link>
    <joint name="weld" type="fixed"><parent link="base"/><child link="a"/></joint>
    <joint name="j" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
      <mimic joint="weld"/></joint></robot>)";
  CHECK_THAT(error_of(urdf), Equals("bad.urdf: joint 'j' <mimic>: unknown or fixed joint 'weld'"));
}

TEST_CASE("mutated URDFs load or fail with one line, never crash", "[urdf][fuzz]") {
  // Replace attribute values and drop elements of the bundled URDFs at random.
  const char* values[] = {"nan", "-1", "", "1e400", "0 0 0", "abc", "1 2", "0", "inf", "-0.5 2 1"};
  std::mt19937 rng(11);
  int loaded = 0, refused = 0;
  for (const char* name : {"urdf/arm7.urdf", "urdf/hand16.urdf", "urdf/gantry.urdf"}) {
    std::ifstream in(model_path(name));
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (int k = 0; k < 150; ++k) {
      std::string t = text;
      for (int edits = 1 + static_cast<int>(rng() % 3); edits > 0; --edits) {
        if (rng() % 4 == 0) {  // drop one element <tag …/> or <tag …>…</tag> opening line
          const std::size_t at = t.find('<', rng() % t.size());
          const std::size_t end = at == std::string::npos ? at : t.find('>', at);
          if (end != std::string::npos) t.erase(at, end - at + 1);
        } else {  // replace one attribute value
          const std::size_t at = t.find("=\"", rng() % t.size());
          const std::size_t end = at == std::string::npos ? at : t.find('"', at + 2);
          if (end != std::string::npos)
            t.replace(at + 2, end - at - 2, values[rng() % std::size(values)]);
        }
      }
      try {
        const Model m = load_urdf_text(t);
        Workspace ws(m);
        const VecX q = VecX::Constant(m.n(), 0.2);
        const Status st = forward_dynamics(m, ws, q, q, q);
        CHECK((st.ok ? ws.qdd.allFinite() : !st.message.empty()));
        ++loaded;
      } catch (const ModelError& e) {
        const std::string msg = e.what();
        CHECK(msg.find('\n') == std::string::npos);
        CHECK(msg.find("robot.urdf") != std::string::npos);
        ++refused;
      }
    }
  }
  CHECK(loaded > 0);
  CHECK(refused > 0);
}

TEST_CASE("a URDF link with inertia but zero mass is a pure rotary inertia", "[urdf]") {
  // Some exporters write placeholder links (or rotors) this way; Simbody cannot hold them, so
  // the closed form checks it: a rotor on an x axis has M^s = e_xᵀ (R J Rᵀ) e_x.
  const Model m = load_urdf_text(
      R"(<robot name="r"><link name="base"/><link name="rotor"><inertial>
           <origin xyz="0 0 0" rpy="0.3 0.2 0.1"/><mass value="0"/>
           <inertia ixx="0.002" iyy="0.003" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial></link>
         <joint name="spin" type="continuous"><parent link="base"/><child link="rotor"/>
           <axis xyz="1 0 0"/></joint></robot>)");
  const auto Rot = [](int axis, double a) { return Mat3(Eigen::AngleAxisd(a, Vec3::Unit(axis))); };
  const Mat3 R = Rot(2, 0.1) * Rot(1, 0.2) * Rot(0, 0.3);
  const Mat3 J = R * Vec3(0.002, 0.003, 0.004).asDiagonal() * R.transpose();
  Workspace ws(m);
  evaluate(m, ws, VecX::Constant(1, 0.7), VecX::Constant(1, 3.0), VecX());
  CHECK(ws.Ms(0, 0) == Approx(J(0, 0)).epsilon(1e-12));
  CHECK(std::abs(ws.h[0]) < 1e-15);  // spinning about a fixed axis: no velocity force on it
}

TEST_CASE("URDF floating and planar joints load as free and planar joints", "[urdf]") {
  const std::string ok_inertial = inertial(2.0, "0 0.1 0", "0 0 0", 0.1, 0.2, 0.25);
  const Model f = load_urdf_text(one_link(ok_inertial, "", "1 0 0", "floating"));
  REQUIRE(f.bodies.size() == 1);
  CHECK(f.bodies[0].joint.type == JointType::Free);
  CHECK(f.n() == 6);
  CHECK(f.n_q() == 7);
  const Model p = load_urdf_text(one_link(ok_inertial, "", "0 0 2", "planar"));
  CHECK(p.bodies[0].joint.type == JointType::Planar);
  CHECK(p.bodies[0].joint.axis.isApprox(Vec3::UnitZ()));
  CHECK(p.coordinate_names == std::vector<std::string>{"j.x", "j.y", "j.theta"});
}

TEST_CASE("URDF with a floating base: a free root, in free fall every joint keeps still",
          "[urdf]") {
  // Uniform gravity on a free mechanism at rest accelerates every body by g: the base's
  // linear acceleration (in its own axes) is Rᵀg, and no joint accelerates.
  for (const char* robot : {"atlas.urdf", "hyq.urdf"}) {
    INFO(robot);
    const std::string path = std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/" + robot;
    LoadOptions o;
    o.floating_base = true;
    const Model m = load_model(path, o);
    REQUIRE(m.bodies[0].joint.type == JointType::Free);
    REQUIRE(m.bodies[0].parent == -1);
    CHECK(m.n_q() == m.n() + 1);
    Workspace ws(m);
    std::mt19937 rng(4);
    const VecX q = random_posture(m, rng);
    REQUIRE(forward_dynamics(m, ws, q, VecX::Zero(m.n()), VecX::Zero(m.n())).ok);
    const Mat3 R = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).toRotationMatrix();
    CHECK((ws.qdd.head<3>() - R.transpose() * m.gravity).norm() < 1e-10 * m.gravity.norm());
    CHECK(ws.qdd.segment<3>(3).norm() < 1e-10);
    CHECK(ws.qdd.tail(m.n() - 6).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("xacro: only what needs expanding is refused, naming where", "[urdf][xacro]") {
  // A declaration alone (exported URDFs keep xmlns:xacro on <robot>) and xacro inside comments
  // need nothing: the file loads. Real cases: bullet3's iiwa (declaration) and Unitree's A1
  // (declaration, and xacro in comments) load.
  const std::string link = R"(<link name="base"/><link name="l">)" +
                           inertial(1, "0.1 0 0", "0 0 0", 0.01, 0.01, 0.01) + "</link>";
  const std::string joint =
      R"(<joint name="j" type="revolute"><parent link="base"/><child link="l"/>)"
      R"(<axis xyz="0 0 1"/></joint>)";
  const std::string declared = R"(<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">)";
  CHECK(load_urdf_text(declared + link + joint + "</robot>").n() == 1);
  CHECK(load_urdf_text(declared + "<!-- <xacro:include filename=\"$(find x)/a.xacro\"/> -->" +
                       link + joint + "</robot>")
            .n() == 1);
  // Any prefix the file binds to xacro's namespace, and substitutions in attributes.
  CHECK_THAT(error_of(R"(<robot name="r" xmlns:x="http://ros.org/wiki/xacro">)" + link +
                      "\n<x:property name=\"a\" value=\"1\"/>" + joint + "</robot>"),
             Catch::StartsWith("bad.urdf: <x:property> at line 2 is a xacro element: the file "
                               "needs xacro"));
  CHECK_THAT(error_of(declared + link +
                      R"(<joint name="j" type="revolute"><origin rpy="0 0 ${pi/2}"/>)"
                      R"(<parent link="base"/><child link="l"/></joint></robot>)"),
             Catch::StartsWith("bad.urdf: <origin> at line 1 has a xacro substitution, "
                               "rpy='0 0 ${pi/2}': the file needs xacro"));
  // Real files (tests/data/urdf/README.md).
  const std::string data = std::string(FEMDYN_SOURCE_DIR) + "/tests/data/urdf/";
  CHECK(load_model(data + "bullet3_kuka_iiwa.urdf").n() == 7);
  CHECK(load_model(data + "unitree_a1.urdf").n() == 12);
  // The extension in any case; a .xacro file is read to say what it needs.
  const std::string upper = write_temp("robot.URDF", declared + link + joint + "</robot>");
  CHECK(load_model(upper).n() == 1);
  const std::string macro =
      write_temp("arm.urdf.xacro", declared + "<xacro:macro name=\"m\"/></robot>");
  CHECK_THROWS_WITH(load_model(macro), Catch::Contains("<xacro:macro> at line 1 is a xacro "
                                                       "element: the file needs xacro"));
}

TEST_CASE("an inertia's round-off is judged against m L², not against the tensor itself",
          "[urdf][inertia]") {
  // iCub's point-mass links carry export noise (−2.4e-35) in a zero tensor: round-off against
  // m L² (L the model's largest offset, here 0.3 m), so the link is a point mass. A moment
  // negative beyond 1e-9 m L² is still refused.
  const auto robot = [](const std::string& ixx) {
    return R"(<robot name="r"><link name="base"/><link name="l"><inertial><origin xyz="0.3 0 0"/>)"
           R"(<mass value="0.5"/><inertia ixx=")" +
           ixx +
           R"(" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>)"
           R"(<joint name="j" type="revolute"><parent link="base"/><child link="l"/>)"
           R"(<axis xyz="0 0 1"/></joint></robot>)";
  };
  const Model m = load_urdf_text(robot("-2.40741e-35"));
  Workspace ws(m);
  mass_matrix(m, ws, VecX::Zero(1));
  CHECK(ws.Ms(0, 0) == Approx(0.5 * 0.09).epsilon(1e-12));  // m r², the point mass
  CHECK_THAT(error_of(robot("-1e-9")),
             Equals("bad.urdf: link 'l': inertia has a negative principal moment (-1e-09); the "
                    "balance_inertia option (--balance-inertia) takes the nearest physical "
                    "inertia instead"));
}
