// MechanismBuilder (models/builder.hpp): a mechanism described in code is the model the JSON
// file with the same content loads — every element form, a four-bar law closed by a rod, a
// polynomial of two joints, a linear coupling, springs, a damper, limits and a load — and bad
// arguments get the loader's messages with the same paths.
#include <catch2/catch.hpp>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "elements/space_bar.hpp"
#include "models/builder.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

const char* kJson = R"({"name": "everything", "gravity": [0.3, -9.81, -1.0], "bodies": [
  {"name": "crank", "parent": "world", "joint": {"name": "j1", "type": "revolute",
   "axis": [0, 0, 1]}, "nodes": {"tip": [0.1, 0, 0]},
   "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.2},
                {"type": "rod", "nodes": ["tip", "rocker/tip"], "mass": 0.05}]},
  {"name": "rocker", "parent": "world", "joint": {"name": "j2", "type": "revolute",
   "axis": [0, 0, 1], "origin": {"xyz": [0.3, 0, 0]}}, "nodes": {"tip": [0.2, 0, 0]},
   "elements": [{"type": "lumped_point", "node": "tip", "mass": 0.3},
                {"type": "rotary_node", "node": [0.1, 0, 0],
                 "inertia": [[0.001, 0.0001, 0], [0.0001, 0.002, 0], [0, 0, 0.0025]]}]},
  {"name": "arm", "parent": "rocker", "joint": {"name": "j3", "type": "revolute",
   "axis": [0, 1, 0.2], "origin": {"xyz": [0.2, 0, 0], "rpy": [0.1, 0.2, 0.3]},
   "spring": {"stiffness": 2, "rest": 0.3}, "damping": 0.05},
   "elements": [{"type": "rigid_body", "mass": 0.5, "com": [0.1, 0, 0.01],
                 "inertia": [[0.002, 0.0002, 0], [0.0002, 0.003, 0.0001], [0, 0.0001, 0.004]]}]},
  {"name": "slider", "parent": "arm", "joint": {"name": "j4", "type": "prismatic",
   "axis": [1, 0.2, 0], "origin": {"xyz": [0.25, 0, 0]}, "limits": [-0.2, 0.3]},
   "elements": [{"type": "space_bar", "nodes": [[0, 0, 0], [0.2, 0.02, 0]], "mass": 0.4,
                 "inertia": [[0.0001, 0, 0], [0, 0.0014, 0], [0, 0, 0.0014]]}]},
  {"name": "hand", "parent": "slider", "joint": {"name": "j5", "type": "revolute",
   "axis": [1, 0, 0], "origin": {"xyz": [0.2, 0.02, 0]}},
   "elements": [{"type": "lumped_point", "node": [0, 0.05, 0], "mass": 0.1},
                {"type": "space_bar", "nodes": [[0, 0, 0], [0.01, 0.1, 0.02]], "density": 2700,
                 "area": 1e-4, "Iy": 2e-9, "Iz": 3e-9, "section_y": [1, 0, 0.3]}]},
  {"name": "finger", "parent": "hand", "joint": {"name": "j6", "type": "revolute",
   "axis": [0, 0, 1], "origin": {"xyz": [0, 0.05, 0]}},
   "elements": [{"type": "lumped_point", "node": [0.04, 0, 0], "mass": 0.05}]}],
  "couplings": [
    {"joint": "j2", "follows": "j1", "four_bar": {"ground": 0.3, "input": 0.1, "coupler": 0.35,
     "output": 0.2, "output_offset": 0}},
    {"joint": "j5", "follows": ["j3", "j4"], "polynomial": [[0.5, 1, 0], [0.2, 1, 1]]},
    {"joint": "j6", "follows": [{"joint": "j3", "ratio": -0.7}], "offset": 0.1}],
  "loads": [{"body": "arm", "point": [0.1, 0, 0.05], "force": [1, -2, 0.5],
             "torque": [0.1, 0, -0.2]}]})";

JointSpec revolute(const std::string& name, const Vec3& axis, const Vec3& xyz = Vec3::Zero()) {
  JointSpec j;
  j.name = name;
  j.type = JointType::Revolute;
  j.axis = axis;
  j.xyz = xyz;
  return j;
}

Mat3 tensor(double xx, double yy, double zz, double xy, double xz, double yz) {
  return (Mat3() << xx, xy, xz, xy, yy, yz, xz, yz, zz).finished();
}

MechanismBuilder everything() {
  MechanismBuilder b("everything");
  b.gravity({0.3, -9.81, -1.0});
  b.body("crank", "world", revolute("j1", Vec3::UnitZ()));
  b.node("crank", "tip", {0.1, 0, 0});
  b.body("rocker", "world", revolute("j2", Vec3::UnitZ(), {0.3, 0, 0}));
  b.node("rocker", "tip", {0.2, 0, 0});
  b.lumped_point("crank", std::string("tip"), 0.2);
  b.rod("crank", std::string("tip"), std::string("rocker/tip"), 0.05);
  b.lumped_point("rocker", std::string("tip"), 0.3);
  b.rotary_node("rocker", Vec3(0.1, 0, 0), tensor(0.001, 0.002, 0.0025, 0.0001, 0, 0));
  JointSpec j3 = revolute("j3", {0, 1, 0.2}, {0.2, 0, 0});
  j3.rpy = {0.1, 0.2, 0.3};
  j3.stiffness = 2;
  j3.rest = 0.3;
  j3.damping = 0.05;
  b.body("arm", "rocker", j3);
  b.rigid_body("arm", 0.5, {0.1, 0, 0.01}, tensor(0.002, 0.003, 0.004, 0.0002, 0, 0.0001));
  JointSpec j4;
  j4.name = "j4";
  j4.type = JointType::Prismatic;
  j4.axis = {1, 0.2, 0};
  j4.xyz = {0.25, 0, 0};
  j4.lower = -0.2;
  j4.upper = 0.3;
  b.body("slider", "arm", j4);
  b.space_bar("slider", Vec3(0, 0, 0), Vec3(0.2, 0.02, 0), 0.4,
              tensor(0.0001, 0.0014, 0.0014, 0, 0, 0));
  b.body("hand", "slider", revolute("j5", Vec3::UnitX(), {0.2, 0.02, 0}));
  b.lumped_point("hand", Vec3(0, 0.05, 0), 0.1);
  b.space_bar("hand", Vec3(0, 0, 0), Vec3(0.01, 0.1, 0.02),
              BarSection{2700, 1e-4, 2e-9, 3e-9, Vec3(1, 0, 0.3)});
  b.body("finger", "hand", revolute("j6", Vec3::UnitZ(), {0, 0.05, 0}));
  b.lumped_point("finger", Vec3(0.04, 0, 0), 0.05);
  FourBarCoupling::Geometry g;
  g.ground = 0.3, g.input = 0.1, g.coupler = 0.35, g.output = 0.2;
  b.coupling("j2", {"j1"}, std::make_shared<FourBarCoupling>(g));
  b.coupling("j5", {"j3", "j4"},
             std::make_shared<PolynomialCoupling>(
                 2, std::vector<PolynomialCoupling::Term>{{0.5, {1, 0}}, {0.2, {1, 1}}}));
  b.coupling("j6", {{"j3", -0.7}}, 0.1);
  b.load("arm", {0.1, 0, 0.05}, {1, -2, 0.5}, {0.1, 0, -0.2});
  return b;
}

}  // namespace

TEST_CASE("a model from the builder is the model from the same JSON", "[builder]") {
  const Model a = everything().build();
  const Model b = load_text(kJson);
  REQUIRE(a.coordinate_names == b.coordinate_names);
  REQUIRE(a.n_u() == b.n_u());
  REQUIRE(a.elements.size() == b.elements.size());
  for (std::size_t e = 0; e < a.elements.size(); ++e) {
    INFO("element " << e);
    CHECK(a.elements[e].table_row == b.elements[e].table_row);
    CHECK(a.elements[e].node_labels == b.elements[e].node_labels);
    CHECK(a.elements[e].element->local_mass() == b.elements[e].element->local_mass());
  }
  for (int i = 0; i < a.n_u(); ++i) CHECK(a.dof_name(i) == b.dof_name(i));
  Workspace wa(a), wb(b);
  std::mt19937 rng(7);
  for (int k = 0; k < 10; ++k) {
    const VecX q = random_posture(b, rng), qd = random_uniform(b.n(), 2, rng),
               tau = random_uniform(b.n(), 1, rng);
    evaluate(a, wa, q, qd, tau);
    evaluate(b, wb, q, qd, tau);
    CHECK(wa.Ms == wb.Ms);  // the same arithmetic: equal to the bit
    CHECK(wa.h == wb.h);
    CHECK(wa.Q == wb.Q);
    REQUIRE(forward_dynamics(a, wa, q, qd, tau).ok);
    REQUIRE(forward_dynamics(b, wb, q, qd, tau).ok);
    CHECK(wa.qdd == wb.qdd);
    CHECK(energy(a, wa, q, qd).total() == energy(b, wb, q, qd).total());
  }
}

TEST_CASE("the builder refuses bad arguments with the loader's paths", "[builder][errors]") {
  MechanismBuilder b("arm");
  b.body("link", "world", revolute("j", Vec3::UnitZ()));
  CHECK_THROWS_WITH(b.lumped_point("link", Vec3(0, 0, -1), -1),
                    "arm (builder): /bodies/0/elements/0/mass: must be positive, got -1");
  CHECK_THROWS_WITH(b.lumped_point("link", std::string("tip"), 1),
                    "arm (builder): /bodies/0/elements/0/node: unknown node 'tip' (not in the "
                    "body's nodes)");
  CHECK_THROWS_WITH(b.lumped_point("nope", Vec3(0, 0, 0), 1),
                    Catch::Contains("unknown body 'nope'"));
  CHECK_THROWS_WITH(b.rotary_node("link", Vec3(0, 0, 0), tensor(1, 1, 3, 0, 0, 0)),
                    Catch::StartsWith("arm (builder): /bodies/0/elements/0/inertia: ") &&
                        Catch::Contains("triangle"));
  CHECK_THROWS_WITH(b.rigid_body("link", 1, Vec3(0, std::nan(""), 0), Mat3::Identity()),
                    "arm (builder): /bodies/0/elements/0/com: centre of mass is NaN or Inf");
  CHECK_THROWS_WITH(b.space_bar("link", Vec3(1, 0, 0), Vec3(1, 0, 0), 1, Mat3::Identity()),
                    Catch::Contains("the two nodes of a space bar coincide"));
  CHECK_THROWS_WITH(
      b.space_bar("link", Vec3(0, 0, 0), Vec3(1, 0, 0), BarSection{2700, 1e-4, -1, 1e-9, {}}),
      "arm (builder): /bodies/0/elements/0/Iy: must be positive, got -1");
  CHECK_THROWS_WITH(b.space_bar("link", Vec3(0, 0, 0), Vec3(1, 0, 0),
                                BarSection{2700, 1e-4, 1e-9, 1e-9, Vec3(-2, 0, 0)}),
                    "arm (builder): /bodies/0/elements/0/section_y: is parallel to the bar");
  // What compile() checks is reported by compile(), with the builder's paths.
  b.lumped_point("link", Vec3(0, 0, -1), 1);
  b.body("other", "missing", revolute("k", Vec3::UnitZ()));
  CHECK_THROWS_WITH(b.build(), Catch::StartsWith("arm (builder): /bodies/1"));
}

TEST_CASE("a joint whose type was left out is refused, not welded", "[builder][errors]") {
  // JointSpec's type defaults to fixed: a joint given an axis, limits, a spring or a damper but
  // no type would weld its body to the parent and ignore them. The builder refuses it, naming
  // the joint's path, as the JSON loader refuses the same joint written in a file.
  const std::string loader_says = "a fixed joint has no motion: no axis, limits, spring or damping";
  JointSpec axis;
  axis.axis = Vec3::UnitY();
  JointSpec limits;
  limits.lower = -1, limits.upper = 1;
  JointSpec spring;
  spring.stiffness = 2;
  JointSpec rest;
  rest.rest = 0.3;
  JointSpec damper;
  damper.damping = 0.1;
  for (const auto& [joint, key] : {std::pair{axis, "axis"},
                                   {limits, "limits"},
                                   {spring, "spring"},
                                   {rest, "spring"},
                                   {damper, "damping"}}) {
    INFO(key);
    MechanismBuilder b("arm");
    CHECK_THROWS_WITH(b.body("link", "world", joint),
                      Catch::StartsWith("arm (builder): /bodies/0/joint/" + std::string(key) +
                                        ": " + loader_says));
    CHECK(b.spec().bodies.empty());  // nothing added
  }
  CHECK_THROWS_WITH(load_text(R"({"name": "arm", "bodies": [{"name": "link", "parent": "world",
                    "joint": {"type": "fixed", "damping": 0.1}}]})"),
                    Catch::Contains("/bodies/0/joint/damping: " + loader_says));
  // A fixed joint with an origin only, and the same joint with its type, are accepted.
  MechanismBuilder b("arm");
  JointSpec weld;
  weld.xyz = {0.1, 0, 0};
  b.body("base", "world", weld);
  damper.type = JointType::Revolute;
  b.body("link", "base", damper);
  b.lumped_point("link", Vec3(0.2, 0, 0), 1);
  const Model m = b.build();
  CHECK(m.coordinate_names == std::vector<std::string>{"link"});
}
