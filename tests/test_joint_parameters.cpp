// Every joint type, driven from the list of joint type names (core/model/joint_type.hpp) and
// what each type declares it reads (core/joints/parameters.hpp): a new type is tested here
// without a line added. Each one is written in JSON and by the C++ builder from its declaration
// alone, and must give the same model; its own numbers must land where it says; another type's
// numbers must be refused naming the key; and the model must match its Simbody twin.
#include <catch2/catch.hpp>
#include <string>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/sampling.hpp"
#include "models/builder.hpp"
#include "tests/helpers.hpp"
#include "validation/validate.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// The canonical types (the first name listed for each).
std::vector<JointType> joint_types() {
  std::vector<JointType> out;
  for (const JointTypeName& t : kJointTypeNames)
    if (t.name == joint_type_name(t.type)) out.push_back(t.type);
  return out;
}

const Vec3 kAxis = Vec3(0.2, 0.3, 1).normalized(), kAxis2 = Vec3(1, 0, -0.2).normalized();

std::string exact(double x) { return format_number(x, "%.17g"); }
std::string vec_text(const Vec3& v) {
  return "[" + exact(v[0]) + ", " + exact(v[1]) + ", " + exact(v[2]) + "]";
}

// The joint as its type declares it, with each of its numbers at the declared example, and
// `extra` JSON members added.
std::string joint_json(JointType type, const std::string& extra = "") {
  const JointParameters p = joint_parameters(type);
  std::string j = R"({"type": ")" + std::string(joint_type_name(type)) +
                  R"(", "origin": {"xyz": [0.1, -0.2, 0.3], "rpy": [0.2, 0.1, -0.3]})";
  if (p.axes != JointAxes::None) j += R"(, "axis": )" + vec_text(kAxis);
  if (p.axes == JointAxes::Two) j += R"(, "axis2": )" + vec_text(kAxis2);
  for (const JointScalar& s : p.scalars)
    j += R"(, ")" + std::string(s.key) + R"(": )" + exact(s.example);
  return j + extra + "}";
}

// A base on the type's joint and a revolute child, rigid bodies with full inertias.
std::string model_json(JointType type, const std::string& extra = "") {
  const std::string inertia = R"("inertia": {"ixx": 0.03, "iyy": 0.04, "izz": 0.05,
      "ixy": 0.002, "ixz": -0.001, "iyz": 0.003})";
  return R"({"name": "one type", "gravity": [0.3, -0.2, -9.81], "bodies": [
    {"name": "a", "parent": "world", "joint": )" +
         joint_json(type, extra) +
         R"(, "elements": [{"type": "rigid_body", "mass": 1.3, "com": [0.05, -0.02, 0.1], )" +
         inertia + R"(}]},
    {"name": "b", "parent": "a", "joint": {"type": "revolute", "axis": [0, 1, 0],
      "origin": {"xyz": [0.3, 0, 0]}},
      "elements": [{"type": "rigid_body", "mass": 0.7, "com": [0.1, 0, 0], )" +
         inertia + "}]}]}";
}

// The same mechanism by the C++ builder, the joint from the type's declaration.
Model built(JointType type) {
  const JointParameters p = joint_parameters(type);
  const Mat3 I =
      (Mat3() << 0.03, 0.002, -0.001, 0.002, 0.04, 0.003, -0.001, 0.003, 0.05).finished();
  MechanismBuilder b("one type");
  b.gravity(Vec3(0.3, -0.2, -9.81));
  JointSpec j;
  j.type = type;
  j.xyz = Vec3(0.1, -0.2, 0.3);
  j.rpy = Vec3(0.2, 0.1, -0.3);
  if (p.axes != JointAxes::None) j.axis = kAxis;
  if (p.axes == JointAxes::Two) j.axis2 = kAxis2;
  for (const JointScalar& s : p.scalars) j.scalars[std::string(s.key)] = s.example;
  b.body("a", "world", j);
  b.rigid_body("a", 1.3, Vec3(0.05, -0.02, 0.1), I);
  JointSpec r;
  r.type = JointType::Revolute;
  r.axis = Vec3::UnitY();
  r.xyz = Vec3(0.3, 0, 0);
  b.body("b", "a", r);
  b.rigid_body("b", 0.7, Vec3(0.1, 0, 0), I);
  return b.build();
}

}  // namespace

TEST_CASE("every joint type from its declaration: JSON and builder agree, its numbers land") {
  for (const JointType type : joint_types()) {
    INFO(joint_type_name(type));
    const Model m = load_text(model_json(type));
    const Model b = built(type);
    const Joint& J = m.bodies[0].joint;
    for (const JointScalar& s : joint_parameters(type).scalars) CHECK(J.*(s.value) == s.example);
    REQUIRE(m.n() == b.n());
    Workspace wm(m), wb(b);
    std::mt19937 rng(7);
    for (int k = 0; k < 3; ++k) {
      const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 1.0, rng);
      evaluate(m, wm, q, qd, VecX::Zero(m.n()));
      evaluate(b, wb, q, qd, VecX::Zero(m.n()));
      CHECK(rel_error(wm.Ms, wb.Ms) < 1e-14);
      CHECK(rel_error(wm.h, wb.h) < 1e-14);
      CHECK(rel_error(wm.Q, wb.Q) < 1e-14);
    }
  }
}

TEST_CASE("every joint type refuses another type's numbers, naming the key") {
  for (const JointType type : joint_types())
    for (const JointType other : joint_types())
      for (const JointScalar& s : joint_parameters(other).scalars) {
        if (joint_scalar(type, s.key)) continue;
        INFO(joint_type_name(type) << " given " << s.key);
        const std::string why =
            text_error(model_json(type, R"(, ")" + std::string(s.key) + R"(": 0.1)"));
        CHECK_THAT(why, Catch::Contains("/bodies/0/joint/" + std::string(s.key)));
        CHECK_THAT(why, Catch::Contains(joint_scalar_refusal(s.key)));
      }
  // The axes each type does not read, refused in the words its declaration gives.
  for (const JointType type : joint_types()) {
    INFO(joint_type_name(type));
    const JointParameters p = joint_parameters(type);
    if (p.moves && p.axes == JointAxes::None)
      CHECK_THAT(
          text_error(model_json(type, R"(, "axis": [0, 0, 1])")),
          Catch::Contains("/bodies/0/joint/axis") && Catch::Contains(joint_axis_refusal(type)));
    if (p.moves && p.axes == JointAxes::One)
      CHECK_THAT(
          text_error(model_json(type, R"(, "axis2": [1, 0, 0])")),
          Catch::Contains("/bodies/0/joint/axis2") && Catch::Contains(joint_axis2_refusal()));
  }
  CHECK(joint_axis2_refusal() == "only a universal joint has a second axis");
  CHECK(joint_scalar_refusal("pitch") == "only a helical joint has a pitch");
  CHECK(joint_scalar_refusal("lead") == "no joint type has a lead");
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("every joint type from its declaration matches its Simbody twin") {
  for (const JointType type : joint_types()) {
    INFO(joint_type_name(type));
    validation::ValidationOptions o;
    o.states = 5;
    o.t_end = 0.05;
    const validation::ValidationReport r = validation::validate(load_text(model_json(type)), o);
    INFO(r.failure);
    CHECK(r.pass());
  }
}
#endif

TEST_CASE("every joint type's chart Jacobian is the derivative of its chart rate at ξ = 0") {
  // The top-left block of every linearisation (sim/stability.cpp, core/derivatives): a type
  // that moves on a manifold and gave 0 here would linearise about the wrong chart.
  for (const JointType type : joint_types()) {
    INFO(joint_type_name(type));
    const Model m = load_text(model_json(type));
    std::mt19937 rng(3);
    for (int k = 0; k < 3; ++k) {
      const VecX q = random_posture(m, rng), v = random_uniform(m.n(), 2.0, rng);
      const MatX A = chart_rate_jacobian(m, v);
      MatX by_differences(m.n(), m.n());
      const double h = 1e-6;
      for (int j = 0; j < m.n(); ++j) {
        const VecX e = VecX::Unit(m.n(), j) * h;
        by_differences.col(j) = (chart_rates(m, q, e, v) - chart_rates(m, q, -e, v)) / (2 * h);
      }
      CHECK((A - by_differences).cwiseAbs().maxCoeff() < 1e-8);  // (central differences: h²)
      if (is_flat(m.bodies[0].joint))
        CHECK(A.isZero(0));
      else
        CHECK(A.norm() > 0.1);  // (the rates are O(1): the block is not 0)
    }
  }
}
