// MJCF import (io/mjcf_loader.hpp) by relations and refusals, without MuJoCo: fullinertia,
// <frame>, equalities where the model is written, what is reported and what is refused
// (tests/test_mjcf.cpp compares with MuJoCo's compile).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "core/equations.hpp"
#include "core/loops/assembly.hpp"
#include "core/loops/constraint_kinematics.hpp"
#include "core/sampling.hpp"
#include "io/model_loader.hpp"
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
  refused("mesh.xml", "<body><joint/><geom type=\"mesh\" mesh=\"m\"/></body>",
          "<asset><mesh name=\"m\" file=\"m.stl\"/></asset>",
          "<geom> (line 1): the body's mass comes from mesh 'm' (file 'm.stl')");
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
