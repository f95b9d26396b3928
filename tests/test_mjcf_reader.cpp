// MJCF import (io/mjcf_loader.hpp) by relations and refusals, without MuJoCo: fullinertia,
// <frame>, equalities where the model is written, what is reported and what is refused
// (tests/test_mjcf.cpp compares with MuJoCo's compile).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/loops/constraint_kinematics.hpp"
#include "models/model_files.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string mjcf_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/tests/data/mjcf/" + name;
}

std::string load_error(const std::string& path) {
  try {
    (void)load_model(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(loaded)";
}

}  // namespace

TEST_CASE("MJCF: what femdyn does not model is reported in one line, never dropped silently",
          "[mjcf]") {
  std::vector<std::string> warnings;
  LoadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  (void)load_model(mjcf_path("dm_control/swimmer.xml"), options);
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("not modelled by femdyn (listed, not used)") &&
                              Catch::Contains("fluid forces") &&
                              Catch::Contains("6 sensor elements") &&
                              Catch::Contains("7 geoms' contacts"));
}

TEST_CASE("MJCF: bad or unread input is one line naming the file, the element and its line",
          "[mjcf][errors]") {
  Scratch scratch("mjcf_errors");
  const auto write = [&](const std::string& name, const std::string& body,
                         const std::string& head = "") {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << "<mujoco>" << head << "<worldbody>" << body << "</worldbody></mujoco>";
    return path;
  };
  const std::string arm = "<geom type=\"capsule\" size=\"0.02 0.1\"/>";
  const auto refused = [&](const std::string& name, const std::string& body,
                           const std::string& head, const std::string& expected) {
    INFO(name);
    const std::string message = load_error(write(name, body, head));
    CHECK_THAT(message, Catch::Contains(name) && Catch::Contains(expected));
    CHECK(message.find('\n') == std::string::npos);
  };
  const std::string mesh_geom = "<body><joint/><geom type=\"mesh\" mesh=\"m\"/></body>";
  refused("mesh.xml", mesh_geom, "<asset><mesh name=\"m\" file=\"m.stl\"/></asset>",
          "<geom> (line 1): mesh 'm': ");
  refused("dae.xml", mesh_geom, "<asset><mesh name=\"m\" file=\"m.dae\"/></asset>",
          "a mesh femdyn does not read (.dae)");
  refused("hull.xml", mesh_geom,
          "<asset><mesh name=\"m\" vertex=\"0 0 0 1 0 0 0 1 0 1 1 0 0.3 0.2 0\"/></asset>",
          "<mesh name='m'> (line 1): the vertices: its convex hull bounds no volume (the vertices "
          "are all on one plane or line)");
  refused("three.xml", mesh_geom, "<asset><mesh name=\"m\" vertex=\"0 0 0 1 0 0 0 1 0\"/></asset>",
          "its convex hull bounds no volume (3 vertices; a solid needs 4)");
  refused("flat.xml", mesh_geom,
          "<asset><mesh name=\"m\" vertex=\"0 0 0 1 0 0 0 1 0\" face=\"0 1 2 0 2 1\"/></asset>",
          "bounds no volume");
  refused("shell_inertia.xml", mesh_geom,
          "<asset><mesh name=\"m\" inertia=\"shell\" vertex=\"0 0 0 1 0 0 0 1 0 0 0 1\" "
          "face=\"0 2 1 0 1 3 1 2 3 0 3 2\"/></asset>",
          "inertia=\"shell\"");
  refused("shell.xml",
          "<body><joint/><geom type=\"mesh\" mesh=\"m\" shellinertia=\"true\"/></body>",
          "<asset><mesh name=\"m\" vertex=\"0 0 0 1 0 0 0 1 0 0 0 1\" face=\"0 2 1 0 1 3 1 2 3 0 3 "
          "2\"/></asset>",
          "shellinertia");
  refused("nomesh.xml", mesh_geom, "", "mesh 'm' is not an <asset> <mesh>");
  refused("class.xml", "<body><joint class=\"nope\"/>" + arm + "</body>", "",
          "<joint> (line 1): class 'nope' is not defined");
  refused("two.xml", "<body quat=\"1 0 0 0\" euler=\"0 0 1\"><joint/>" + arm + "</body>", "",
          "more than one orientation");
  refused("free.xml", "<body><joint/>" + arm + "<body><freejoint/>" + arm + "</body></body>", "",
          "a free joint must be the only joint of a body at the top of the tree");
  refused("axis.xml", "<body><joint axis=\"0 0 0\"/>" + arm + "</body>", "", "axis is zero");
  refused("nan.xml", "<body pos=\"0 nan 0\"><joint/>" + arm + "</body>", "", "NaN or Inf");
  refused("global.xml", "<body><joint/>" + arm + "</body>", "<compiler coordinate=\"global\"/>",
          "coordinate=\"global\" is refused");
  refused("frame.xml", "<body><frame><joint/></frame>" + arm + "</body>", "",
          "a joint inside a <frame> is not read yet");
  refused("empty.xml", "", "", "<worldbody> holds no body");
  std::string deep;  // 100 bodies nested: beyond the XML reader's depth, and MuJoCo's
  for (int k = 0; k < 100; ++k) deep += "<body><joint/>" + arm;
  for (int k = 0; k < 100; ++k) deep += "</body>";
  refused("deep.xml", deep, "", "elements nested deeper than 100 at line 1");
  const std::string twice =
      write("twice.xml", "", "<include file=\"part.xml\"/><include file=\"part.xml\"/>");
  std::ofstream((scratch.dir / "part.xml").string()) << "<mujoco/>";
  CHECK_THAT(load_error(twice), Catch::Contains("the file is included twice"));
}

// A <frame> (MuJoCo 3, which the 2.2 peer cannot read) is a relation: the bodies in a frame
// equal the same bodies with the frame's pose composed into theirs.
TEST_CASE("MJCF: a body in a <frame> is the body with the frame's pose composed", "[mjcf]") {
  Scratch scratch("mjcf_frame");
  const auto write = [&](const std::string& name, const std::string& body) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << "<mujoco><compiler angle=\"radian\"/><worldbody><body name=\"a\">"
                           "<joint name=\"j1\"/><geom type=\"box\" size=\"0.1 0.05 0.02\"/>"
                        << body << "</body></worldbody></mujoco>";
    return path;
  };
  const std::string inner =
      "<joint name=\"j2\" axis=\"1 0 0\"/><geom type=\"capsule\" fromto=\"0 0 0 0.2 0 0\" "
      "size=\"0.02\"/>";
  const Model framed = load_model(write("framed.xml",
                                        "<frame pos=\"0.1 0.2 0\" axisangle=\"0 0 1 0.5\"><body "
                                        "name=\"b\" pos=\"0.3 0 0\">" +
                                            inner + "</body></frame>"));
  // The frame's pose (0.1, 0.2, 0) turned by 0.5 rad about z, then the body's (0.3, 0, 0).
  const double c = std::cos(0.5), s = std::sin(0.5);
  char pos[200];
  std::snprintf(pos, sizeof pos, "pos=\"%.17g %.17g 0\" axisangle=\"0 0 1 0.5\"", 0.1 + 0.3 * c,
                0.2 + 0.3 * s);
  const Model direct = load_model(
      write("direct.xml", "<body name=\"b\" " + std::string(pos) + ">" + inner + "</body>"));
  Workspace wa(framed), wb(direct);
  std::mt19937 rng(5);
  const VecX q = random_posture(framed, rng), qd = random_uniform(framed.n(), 1, rng);
  inverse_dynamics(framed, wa, q, qd, qd);
  inverse_dynamics(direct, wb, q, qd, qd);
  CHECK(rel_error(wa.tau, wb.tau) < 1e-14);
  CHECK(wa.tau.norm() > 1e-3);
}

// An equality holds where the model is written (MuJoCo computes connect's second point and
// weld's pose there): the loops close at femdyn's initial configuration (q = qpos0, refs).
TEST_CASE("MJCF: connect, weld and joint equalities hold in the model as written", "[mjcf]") {
  const Model m = load_model(mjcf_path("loops.xml"));
  REQUIRE(m.constraints.size() == 2);
  CHECK(m.n() == 6);  // 7 hinges and slides, one following another (a2 = 0.5 a1 + 0.1)
  Workspace ws(m);
  ConstraintKinematics k(m);
  VecX q = neutral_posture(m);
  CHECK(q[0] == Approx(20 * std::numbers::pi / 180));  // crank's ref: q is MuJoCo's qpos
  const AssemblyReport r = assemble(m, ws, k, q);
  CHECK(r.status.ok);
  CHECK(r.iterations == 0);
  CHECK(r.residual < 1e-14);
  // A turned crank opens the loop.
  VecX moved = neutral_posture(m);
  moved[0] += 0.1;
  const AssemblyReport r2 = assemble(m, ws, k, moved);
  CHECK(r2.iterations > 0);
}

// MuJoCo's compiler finds a full tensor's principal axes by an iteration that stops early (M^s
// off by 1.5e-10 on features.xml's forearm given as fullinertia), so fullinertia is checked by a
// relation instead: R diag(d) Rᵀ written as fullinertia is the same body as diag(d) turned by R.
TEST_CASE("MJCF: fullinertia is the same body as diaginertia turned by quat", "[mjcf]") {
  Scratch scratch("mjcf_fullinertia");
  const Eigen::Quaterniond turn = Eigen::Quaterniond(0.7, 0.1, 0.2, 0.3).normalized();
  const Mat3 I = turn.toRotationMatrix() * Vec3(0.011, 0.012, 0.004).asDiagonal() *
                 turn.toRotationMatrix().transpose();
  const auto write = [&](const std::string& name, const std::string& inertial) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << "<mujoco><worldbody><body name=\"a\" pos=\"0 0 1\">"
                           "<joint name=\"j1\" axis=\"1 0 0\"/><joint name=\"j2\" axis=\"0 1 1\"/>"
                           "<inertial pos=\"0.1 0.2 0.3\" mass=\"0.7\" "
                        << inertial << "/></body></worldbody></mujoco>";
    return path;
  };
  char full[300];
  std::snprintf(full, sizeof full, "fullinertia=\"%.17g %.17g %.17g %.17g %.17g %.17g\"", I(0, 0),
                I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  const Model a = load_model(write("full.xml", full));
  const Model b =
      load_model(write("turned.xml", "quat=\"0.7 0.1 0.2 0.3\" diaginertia=\"0.011 0.012 0.004\""));
  Workspace wa(a), wb(b);
  std::mt19937 rng(3);
  const VecX q = random_posture(a, rng);
  mass_matrix(a, wa, q);
  mass_matrix(b, wb, q);
  CHECK(rel_error(wa.Ms, wb.Ms) < 1e-14);
  CHECK(wa.Ms.norm() > 0.01);
}

namespace {

// A box's corners and faces as MJCF's inline mesh attributes, wound outward.
std::string box_mesh_attributes(const Vec3& lo, const Vec3& hi) {
  std::string v = "vertex=\"";
  for (int k = 0; k < 8; ++k) {
    const bool x = k == 1 || k == 2 || k == 5 || k == 6, y = k == 2 || k == 3 || k == 6 || k == 7;
    char corner[120];
    std::snprintf(corner, sizeof corner, "%.17g %.17g %.17g ", x ? hi.x() : lo.x(),
                  y ? hi.y() : lo.y(), k >= 4 ? hi.z() : lo.z());
    v += corner;
  }
  return v + "\" face=\"0 2 1 0 3 2 4 5 6 4 6 7 0 1 5 0 5 4 1 2 6 1 6 5 2 3 7 2 7 6 3 0 4 3 4 7\"";
}

// τ of two models at the same random states: the largest relative difference.
double tau_difference(const Model& a, const Model& b) {
  Workspace wa(a), wb(b);
  std::mt19937 rng(17);
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    const VecX q = random_posture(a, rng), qd = random_uniform(a.n(), 1, rng);
    inverse_dynamics(a, wa, q, qd, qd);
    inverse_dynamics(b, wb, q, qd, qd);
    worst = std::max(worst, rel_error(wa.tau, wb.tau));
  }
  return worst;
}

}  // namespace

// A mesh geom weighs the solid its mesh bounds: a box mesh equals the box geom, in any pose;
// a non-convex mesh follows MuJoCo's legacy inertia (with a note) unless inertia="exact".
TEST_CASE("MJCF: a mesh geom's mass is the solid its mesh bounds, as MuJoCo computes it",
          "[mjcf][mesh]") {
  Scratch scratch("mjcf_mesh");
  const auto model = [&](const std::string& name, const std::string& assets,
                         const std::string& geoms, std::vector<std::string>* warnings = nullptr) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << "<mujoco><asset>" << assets
                        << "</asset><worldbody><body name=\"a\" pos=\"0 0 1\"><joint/>"
                           "<geom type=\"capsule\" fromto=\"0 0 0 0.3 0 0\" size=\"0.02\"/>"
                           "<body name=\"b\" pos=\"0.3 0 0\"><joint axis=\"1 0 0\"/>"
                        << geoms << "</body></body></worldbody></mujoco>";
    LoadOptions options;
    options.warn = [&](const std::string& w) {
      if (warnings) warnings->push_back(w);
    };
    return load_model(path, options);
  };
  const std::string pose = "pos=\"0.1 0.02 -0.03\" euler=\"20 -35 50\"";
  const Model primitive = model(
      "box.xml", "", "<geom type=\"box\" size=\"0.1 0.03 0.02\" density=\"2700\" " + pose + "/>");
  const Model inline_mesh =
      model("inline.xml",
            "<mesh name=\"m\" " +
                box_mesh_attributes(Vec3(-0.1, -0.03, -0.02), Vec3(0.1, 0.03, 0.02)) + "/>",
            "<geom type=\"mesh\" mesh=\"m\" density=\"2700\" " + pose + "/>");
  CHECK(tau_difference(inline_mesh, primitive) < 1e-13);
  // A box off the mesh's origin, and a mass given instead of a density.
  const Model off = model(
      "off.xml",
      "<mesh name=\"m\" " + box_mesh_attributes(Vec3(0.3, 0.2, 0.1), Vec3(0.5, 0.26, 0.14)) + "/>",
      "<geom type=\"mesh\" mesh=\"m\" mass=\"1.296\"/>");
  const Model off_box =
      model("off_box.xml", "",
            "<geom type=\"box\" size=\"0.1 0.03 0.02\" pos=\"0.4 0.23 0.12\" mass=\"1.296\"/>");
  CHECK(tau_difference(off, off_box) < 1e-13);
  // Two boxes apart in one mesh: MuJoCo's legacy inertia counts more than the solid, and says
  // so; inertia="exact" is the two boxes.
  const std::string two =
      "vertex=\"0 0 0 1 0 0 1 .2 0 0 .2 0 0 0 .2 1 0 .2 1 .2 .2 0 .2 .2 "
      "0 0 .5 .2 0 .5 .2 .2 .5 0 .2 .5 0 0 1.5 .2 0 1.5 .2 .2 1.5 0 .2 1.5\" face=\"0 2 1 0 3 2 4 "
      "5 6 4 6 7 "
      "0 1 5 0 5 4 1 2 6 1 6 5 2 3 7 2 7 6 3 0 4 3 4 7 8 10 9 8 11 10 12 13 14 12 14 15 8 9 13 8 "
      "13 12 9 10 14 9 14 13 10 11 15 10 15 14 11 8 12 11 12 15\"";
  std::vector<std::string> warnings;
  const Model legacy = model("legacy.xml", "<mesh name=\"m\" " + two + "/>",
                             "<geom type=\"mesh\" mesh=\"m\" density=\"700\"/>", &warnings);
  REQUIRE(warnings.size() == 2);  // the contacts, and the mesh
  CHECK_THAT(warnings[0] + warnings[1],
             Catch::Contains("1 mesh is not convex") && Catch::Contains("'m' (×1.73)"));
  const Model exact = model("exact.xml", "<mesh name=\"m\" inertia=\"exact\" " + two + "/>",
                            "<geom type=\"mesh\" mesh=\"m\" density=\"700\"/>");
  const Model boxes =
      model("boxes.xml", "",
            "<geom type=\"box\" size=\"0.5 0.1 0.1\" pos=\"0.5 0.1 0.1\" density=\"700\"/>"
            "<geom type=\"box\" size=\"0.1 0.1 0.5\" pos=\"0.1 0.1 1\" density=\"700\"/>");
  CHECK(tau_difference(exact, boxes) < 1e-13);
  CHECK(tau_difference(legacy, boxes) > 1e-2);
  // Vertices alone: their convex hull (by Qhull, as MuJoCo). A box's corners, points inside it
  // and on its faces, in any order, are the box.
  const std::string cloud =
      "vertex=\"0.3 0.26 0.1  0.4 0.23 0.12  0.5 0.2 0.1  0.3 0.2 0.14  0.5 0.26 0.14 0.45 0.2 "
      "0.13  0.3 0.2 0.1  0.5 0.2 0.14  0.3 0.26 0.14  0.35 0.21 0.11  0.5 0.26 0.1  0.3 0.23 "
      "0.12\"";
  CHECK(tau_difference(model("cloud.xml", "<mesh name=\"m\" " + cloud + "/>",
                             "<geom type=\"mesh\" mesh=\"m\" mass=\"1.296\"/>"),
                       off_box) < 1e-13);
  // inertia="convex" (MuJoCo 3) weighs the hull of a mesh's vertices: of the two boxes apart, the
  // hull of their 16 corners, as those corners alone give it, and more than the two boxes.
  const std::string corners = two.substr(0, two.find("face") - 1);
  const Model convex = model("convex.xml", "<mesh name=\"m\" inertia=\"convex\" " + two + "/>",
                             "<geom type=\"mesh\" mesh=\"m\" density=\"700\"/>");
  CHECK(tau_difference(convex, model("corners.xml", "<mesh name=\"m\" " + corners + "/>",
                                     "<geom type=\"mesh\" mesh=\"m\" density=\"700\"/>")) < 1e-13);
  CHECK(tau_difference(convex, boxes) > 1e-2);
}

// A body's named sites are frames on it, where MuJoCo puts them: a hinge about y at the body's
// origin (1 m up) turns the site at (0.2, 0, 0) in its frame to (0.2 cos q, 0, 1 − 0.2 sin q).
TEST_CASE("MJCF: a body's named sites are the model's frames", "[mjcf][frames]") {
  Scratch scratch("mjcf_sites");
  const std::string path = (scratch.dir / "sites.xml").string();
  std::ofstream(path) << "<mujoco><worldbody><site name='floor'/><body name='arm' pos='0 0 1'>"
                         "<joint axis='0 1 0'/><geom type='capsule' fromto='0 0 0 0.2 0 0' "
                         "size='0.02'/><site name='tip' pos='0.2 0 0' euler='0 0 90'/><site/>"
                         "<site name='arm'/></body></worldbody></mujoco>";
  std::vector<std::string> warnings;
  LoadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  const Model m = load_model(path, options);
  const int tip = find_frame(m, "tip");
  REQUIRE(tip >= 0);
  CHECK(m.frames.size() == m.bodies.size() + 1);  // 'tip' only
  REQUIRE(warnings.size() == 1);
  CHECK_THAT(warnings[0], Catch::Contains("1 sites named like a body or another site") &&
                              Catch::Contains("1 sites outside bodies") &&
                              Catch::Contains("1 unnamed sites"));
  Workspace ws(m);
  FrameKinematics k;
  const double q = 0.3;
  frame_kinematics(m, ws, VecX::Constant(1, q), VecX::Zero(1), tip, FrameAxes::World, k);
  CHECK((k.p - Vec3(0.2 * std::cos(q), 0, 1 - 0.2 * std::sin(q))).norm() < 1e-15);
  // Its axes: the body's turned by 90° about z (euler in degrees, MJCF's default).
  const Mat3 expected = Eigen::AngleAxisd(q, Vec3::UnitY()).toRotationMatrix() *
                        Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitZ()).toRotationMatrix();
  CHECK((k.R - expected).norm() < 1e-14);
}

// A tendon equality holds where MuJoCo writes it: L1 − L1₀ = a0 + a1 (L2 − L2₀) on fixed tendons,
// L₀ the lengths at qpos0 (the joints' refs), whatever the free coordinates.
TEST_CASE("MJCF: tendon equalities hold their fixed tendons' relation", "[mjcf][couplings]") {
  const Model m = load_model(mjcf_path("tendons.xml"));
  CHECK(m.n() == m.n_theta() - 2);  // two joints follow
  const auto theta_of = [&](const VecX& q, const std::string& joint) {
    const VecX theta = m.C_configuration * q + m.theta0_configuration;
    for (const Body& b : m.bodies)
      if (b.joint.name == joint) return theta[b.joint.idx_q];
    FAIL("no joint " << joint);
    return 0.0;
  };
  std::mt19937 rng(8);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_posture(m, rng);
    const auto t = [&](const char* j) { return theta_of(q, j); };
    const double L1 = 0.5 * t("s1") + 0.8 * t("s2") - 0.3 * t("w");
    const double L2 = 1.5 * t("w") + t("e");
    const double L1_0 = 0.5 * 0.2 - 0.3 * -0.4, L2_0 = 1.5 * -0.4 + 0.01;
    CHECK(std::abs((L1 - L1_0) - (0.1 + 2 * (L2 - L2_0))) < 1e-14);
    CHECK(std::abs(t("g2") - t("g1")) < 1e-15);  // the differential, at its length as written
  }
}
