// Every bad-input class gives a one-line error naming the file, the JSON path and the problem.
#include <catch2/catch.hpp>

#include "compile/compile.hpp"
#include "core/model/errors.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using Catch::Matchers::Equals;

namespace {

std::string error_of(const std::string& json) {
  try {
    compile(parse_spec(json, "bad.json"));
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

// A valid two-body chain with one replaceable piece.
std::string chain(
    const std::string& joint2 = R"({"type": "revolute", "axis": [0, 1, 0]})",
    const std::string& elements2 = R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": 1}])",
    const std::string& parent2 = "a") {
  return R"({"name": "t", "bodies": [
    {"name": "a", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1}]},
    {"name": "b", "parent": ")" +
         parent2 + R"(", "joint": )" + joint2 + R"(, "elements": )" + elements2 + "}]}";
}

}  // namespace

TEST_CASE("a valid chain loads", "[errors]") { CHECK(error_of(chain()) == "(no error)"); }

TEST_CASE("malformed JSON names line and column", "[errors]") {
  CHECK_THAT(error_of("{\"name\": \"x\",\n \"bodies\": [}"),
             Catch::StartsWith("bad.json: malformed JSON at line 2, column 13"));
}

TEST_CASE("bad-input classes give their pinned messages", "[errors]") {
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 0, 0]})")),
             Equals("bad.json: /bodies/1/joint/axis: axis is zero"));
  CHECK_THAT(error_of(chain(R"({"type": "hinge", "axis": [0, 0, 1]})")),
             Equals("bad.json: /bodies/1/joint/type: unknown joint type 'hinge' (expected "
                    "revolute, continuous, prismatic, fixed, helical, screw, universal, planar, "
                    "spherical, ball or free)"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "blob", "node": [0, 0, 0]}])")),
             Equals("bad.json: /bodies/1/elements/0/type: unknown element type 'blob' (known: "
                    "lumped_point, space_bar, rotary_node, rigid_body, rod)"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "lumped_point", "node": [0, 0, 0], "mass": 1}])", "arm")),
             Equals("bad.json: /bodies/1/parent: unknown parent body 'arm'"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": -2}])")),
             Equals("bad.json: /bodies/1/elements/0/mass: must be positive, got -2"));
  CHECK_THAT(
      error_of(chain(
          R"({"type": "revolute", "axis": [0, 1, 0]})",
          R"([{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 1, "iyy": 1, "izz": 3}}])")),
      Equals("bad.json: /bodies/1/elements/0/inertia: inertia violates the triangle inequality "
             "(principal moments 1, 1, 3)"));
  CHECK_THAT(
      error_of(chain(
          R"({"type": "revolute", "axis": [0, 1, 0]})",
          R"([{"type": "rotary_node", "node": [0, 0, 0], "inertia": {"ixx": -1, "iyy": 1, "izz": 1}}])")),
      Catch::StartsWith("bad.json: /bodies/1/elements/0/inertia: inertia has a negative principal "
                        "moment"));
  CHECK_THAT(
      error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                     R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": 1, "mas": 2}])")),
      Equals("bad.json: /bodies/1/elements/0/mas: unknown key 'mas'"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "lumped_point", "node": "tip", "mass": 1}])")),
             Equals("bad.json: /bodies/1/elements/0/node: unknown node 'tip' (not in the body's "
                    "\"nodes\")"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": "heavy"}])")),
             Equals("bad.json: /bodies/1/elements/0/mass: expected a number, got string"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": 1e999}])")),
             Equals("bad.json: malformed JSON: number overflow parsing '1e999'"));
}

TEST_CASE("duplicate names and cycles are rejected", "[errors]") {
  CHECK_THAT(error_of(R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"type": "fixed"}},
      {"name": "a", "parent": "world", "joint": {"type": "fixed"}}]})"),
             Equals("bad.json: /bodies/1: duplicate body name 'a'"));
  CHECK_THAT(error_of(R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"name": "j", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]},
      {"name": "b", "parent": "a", "joint": {"name": "j", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}]})"),
             Equals("bad.json: /bodies/1/joint/name: duplicate joint name 'j'"));
  CHECK_THAT(error_of(R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"type": "fixed"}},
      {"name": "b", "parent": "c", "joint": {"type": "fixed"}},
      {"name": "c", "parent": "b", "joint": {"type": "fixed"}}]})"),
             Equals("bad.json: /bodies/1/parent: body 'b' is not connected to the world (its "
                    "parents form a cycle)"));
  CHECK_THAT(error_of(R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]},
      {"name": "b", "parent": "a", "joint": {"name": "j2", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}],
      "couplings": [{"joint": "j1", "follows": "j2"}, {"joint": "j2", "follows": "j1"}]})"),
             Catch::Contains("/couplings/0: couplings form a cycle through joint"));
}

TEST_CASE("a massless chain end makes M^s singular: named at its joint", "[errors]") {
  // Body b has no elements: its joint moves nothing.
  CHECK_THAT(
      error_of(chain(R"({"name": "wrist", "type": "revolute", "axis": [0, 1, 0]})", "[]")),
      Equals(
          "bad.json: /bodies/1/joint: the mass matrix M^s is singular: coordinate "
          "'wrist' moves no inertia (a massless chain end, or all its mass on the joint axis?)"));
  // A point mass on the joint axis also moves no inertia with that joint.
  CHECK_THAT(
      error_of(chain(R"({"name": "spin", "type": "revolute", "axis": [1, 0, 0]})",
                     R"([{"type": "lumped_point", "node": [0.3, 0, 0], "mass": 1}])")),
      Equals("bad.json: /bodies/1/joint: the mass matrix M^s is singular: coordinate "
             "'spin' moves no inertia (a massless chain end, or all its mass on the joint axis?)"));
}

TEST_CASE("explicit correlation tables are checked", "[errors]") {
  const std::string base = R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}],
      "correlation_table": )";
  CHECK(error_of(base + "[[1, 2, 0, 0, 0, 0]]}") == "(no error)");
  CHECK_THAT(error_of(base + "[[1, 2, 0]]}"),
             Equals("bad.json: /correlation_table/0: has 3 entries, expected 6 (6 per element "
                    "node)"));
  CHECK_THAT(error_of(base + "[[1, 1, 0, 0, 0, 0]]}"),
             Equals("bad.json: /correlation_table/0/1: system DOF 1 joins a/(1,0,0).x and "
                    "a/(1,0,0).y, which move differently"));
  CHECK_THAT(error_of(base + "[[1, 3, 0, 0, 0, 0]]}"),
             Equals("bad.json: /correlation_table: system DOF 2 is unused"));
}

TEST_CASE("a mechanism without motion, an empty coupling, and a load a table drops", "[errors]") {
  CHECK_THAT(error_of(R"({"bodies": [{"name": "a", "parent": "world", "joint": {"type": "fixed"},
      "elements": [{"type": "lumped_point", "node": [0, 0, 0], "mass": 1}]}]})"),
             Equals("bad.json: has no movable joint: there is no motion to compute"));
  CHECK_THAT(
      error_of(R"({"bodies": [
      {"name": "a", "parent": "world", "joint": {"name": "j1", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]},
      {"name": "b", "parent": "a", "joint": {"name": "j2", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}],
      "couplings": [{"joint": "j2", "follows": []}]})"),
      Equals("bad.json: /couplings/0/follows: names no joint (to fix a joint, make it fixed)"));
  const auto pendulum = [](const std::string& table) {
    return R"({"bodies": [{"name": "a", "parent": "world",
        "joint": {"type": "revolute", "axis": [0, 0, 1]},
        "elements": [{"type": "lumped_point", "node": [0.5, 0, 0], "mass": 1}]}],
      "loads": [{"body": "a", "point": [0.5, 0, 0], "force": [0, 2, 0]}],
      "correlation_table": )" +
           table + "}";
  };
  CHECK(error_of(pendulum("[[1, 2, 0, 0, 0, 0]]")) == "(no error)");
  CHECK_THAT(error_of(pendulum("[[1, 0, 0, 0, 0, 0]]")),
             Equals("bad.json: /loads/0: the load pushes on a/(0.5,0,0).y, which the correlation "
                    "table leaves out"));
}

TEST_CASE("keys that would be ignored are refused", "[errors]") {
  CHECK_THAT(error_of(chain(R"({"type": "fixed", "axis": [0, 0, 1]})")),
             Equals("bad.json: /bodies/1/joint/axis: a fixed joint has no motion: no axis, "
                    "limits, spring or damping"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "space_bar", "nodes": [[0, 0, 0], [0.3, 0, 0]],
                                 "mass": 1, "inertia": {"ixx": 0, "iyy": 0.01, "izz": 0.01},
                                 "Iy": 1e-8}])")),
             Equals("bad.json: /bodies/1/elements/0/Iy: give either mass and inertia or "
                    "density, area, Iy, Iz"));
  CHECK_THAT(error_of(chain(R"({"type": "revolute", "axis": [0, 1, 0]})",
                            R"([{"type": "space_bar", "nodes": [[0, 0, 0], [0.3, 0, 0]],
                                 "density": 2700, "area": 1e-4, "Iy": 1e-9, "Iz": 1e-9,
                                 "inertia": {"ixx": 0, "iyy": 0.01, "izz": 0.01}}])")),
             Equals("bad.json: /bodies/1/elements/0/inertia: give either mass and inertia or "
                    "density, area, Iy, Iz"));
  CHECK_THAT(error_of(R"({"bodies": [{"name": "a", "parent": "world",
      "joint": {"type": "revolute", "axis": [0, 0, 1]}, "nodes": {"tip": [0.5, 0, 0]},
      "elements": [{"type": "lumped_point", "node": "tip", "mass": 1}]}],
      "loads": [{"body": "a", "node": "tip", "point": [0.5, 0, 0], "force": [0, 1, 0]}]})"),
             Equals("bad.json: /loads/0/point: give either point or node, not both"));
}

TEST_CASE("random_tree plugin parameters are checked", "[errors]") {
  CHECK_THAT(error_of(R"({"model": "random_tree", "params": {"bodies": 0}})"),
             Equals("bad.json: /params/bodies: expected an integer from 1 to 10000"));
  CHECK_THAT(error_of(R"({"model": "random_tree", "params": {"branching": 2}})"),
             Equals("bad.json: /params/branching: expected a number in [0, 1]"));
  CHECK_THAT(error_of(R"({"model": "random_tree", "params": {"seed": 1.5}})"),
             Equals("bad.json: /params/seed: expected an integer >= 0"));
  CHECK(error_of(R"({"model": "random_tree", "params": {"seed": 3, "bodies": 30}})") ==
        "(no error)");
}
