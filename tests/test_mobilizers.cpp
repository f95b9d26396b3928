// The joint types beyond revolute, prismatic and fixed against their Simbody mobilizers
// (validation/twin_mobilizers.cpp, twin_state.cpp): each alone, all in one tree, seeded random
// trees of mixed types, `femdyn validate` on a file, and a twin built wrong that must be seen.
#include <catch2/catch.hpp>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "tests/helpers.hpp"
#include "tests/validation_checks.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

using namespace femdyn;
using namespace femdyn::test;
using validation::ValidationOptions;
using validation::ValidationReport;

namespace {

// A body of full (asymmetric) inertia whose centre of mass is off its origin.
std::string body(const std::string& name, const std::string& parent, const std::string& joint,
                 double mass) {
  return R"({"name": ")" + name + R"(", "parent": ")" + parent + R"(", "joint": )" + joint +
         R"(, "elements": [{"type": "rigid_body", "mass": )" + std::to_string(mass) +
         R"(, "com": [0.05, -0.02, 0.1], "inertia": {"ixx": 0.03, "iyy": 0.04, "izz": 0.05,
            "ixy": 0.002, "ixz": -0.001, "iyz": 0.003}}]})";
}

// Joints of each type with tilted frames and axes off the coordinate axes.
const std::pair<const char*, const char*> kJoints[] = {
    {"helical",
     R"({"type": "helical", "axis": [0.2, 0.3, 1], "pitch": 0.05,
         "origin": {"xyz": [0.1, 0, 0.4], "rpy": [0.2, -0.1, 0.3]}})"},
    {"universal",
     R"({"type": "universal", "axis": [1, 0, 0], "axis2": [0, 0.6, 0.8],
         "origin": {"xyz": [-0.2, 0.1, 0.1], "rpy": [0, 0.4, 0]}})"},
    {"planar",
     R"({"type": "planar", "axis": [0, 1, 1], "origin": {"xyz": [0.1, -0.3, 0], "rpy": [0.3, 0, 0.1]}})"},
    {"spherical",
     R"({"type": "spherical", "origin": {"xyz": [0.2, 0.1, 0.3], "rpy": [0.3, 0, 0.2]}})"},
    {"free", R"({"type": "free", "origin": {"xyz": [0, 0.1, 0.2], "rpy": [0.1, 0.2, 0.3]}})"},
};

// The joint `joint` on the world carrying a revolute link, under a tilted gravity and a load.
std::string alone_json(const std::string& joint) {
  return R"({"name": "alone", "gravity": [0.3, -0.2, -9.81], "bodies": [)" +
         body("a", "world", joint, 1.3) + "," +
         body("link", "a",
              R"({"type": "revolute", "axis": [0, 1, 0.3], "origin": {"xyz": [0.3, 0, 0.1]}})",
              0.6) +
         R"(], "loads": [{"body": "a", "point": [0.1, 0, 0.05], "force": [1, -2, 0.5],
            "torque": [0.1, 0, -0.2]}]})";
}

// Every type in one tree: a free base, the others on it and on each other.
std::string all_joints_json() {
  return R"({"name": "all joints", "gravity": [0.3, -0.2, -9.81], "bodies": [)" +
         body("base", "world", kJoints[4].second, 5.0) + "," +
         body("ball", "base", kJoints[3].second, 1.5) + "," +
         body("cardan", "base", kJoints[1].second, 1.2) + "," +
         body("slider", "base", kJoints[2].second, 0.9) + "," +
         body("screw", "ball", kJoints[0].second, 0.7) + "," +
         body("elbow", "cardan",
              R"({"type": "revolute", "axis": [0, 1, 0], "origin": {"xyz": [0.3, 0, 0]}})", 0.6) +
         "," +
         body("rail", "slider",
              R"({"type": "prismatic", "axis": [1, 0, 0], "origin": {"xyz": [0, 0, 0.2]}})", 0.4) +
         R"(], "loads": [{"body": "screw", "point": [0.1, 0, 0.05], "force": [1, -2, 0.5]},
            {"body": "base", "point": [0, 0, 0], "torque": [0.1, 0, -0.2]}]})";
}

// A seeded random tree of every joint type (a free or spherical joint at most at the root
// and a few below), random axes and offsets.
std::string mixed_tree_json(unsigned seed, int bodies) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> type(0, 6);
  const auto vec = [&](double s) {
    std::ostringstream o;
    o << "[" << s * u(rng) << ", " << s * u(rng) << ", " << s * u(rng) << "]";
    return o.str();
  };
  std::string out = R"({"name": "mixed", "gravity": [0.2, 0.1, -9.81], "bodies": [)";
  for (int b = 0; b < bodies; ++b) {
    const std::string parent =
        b == 0 ? "world" : "b" + std::to_string(std::uniform_int_distribution<int>(0, b - 1)(rng));
    const std::string origin = R"("origin": {"xyz": )" + vec(0.3) + R"(, "rpy": )" + vec(1) + "}";
    const auto draw = [&] {  // (last to first, as GCC evaluated the constructor's unsequenced
                             // arguments: the seeds keep their models)
      const double z = u(rng), y = u(rng), x = u(rng);
      return Vec3(x, y, z);
    };
    const Vec3 a = draw().normalized();
    const Vec3 a2 = a.cross(draw()).normalized();
    std::ostringstream axes;
    axes.precision(17);
    axes << R"("axis": [)" << a.x() << ", " << a.y() << ", " << a.z() << R"(], "axis2": [)"
         << a2.x() << ", " << a2.y() << ", " << a2.z() << "]";
    std::string joint;
    switch (b == 0 ? 6 : type(rng)) {
      case 0:
        joint = R"({"type": "revolute", "axis": )" + vec(1) + ", " + origin + "}";
        break;
      case 1:
        joint = R"({"type": "prismatic", "axis": )" + vec(1) + ", " + origin + "}";
        break;
      case 2:
        joint = R"({"type": "helical", "pitch": 0.03, "axis": )" + vec(1) + ", " + origin + "}";
        break;
      case 3:
        joint = R"({"type": "universal", )" + axes.str() + ", " + origin + "}";
        break;
      case 4:
        joint = R"({"type": "planar", "axis": )" + vec(1) + ", " + origin + "}";
        break;
      case 5:
        joint = R"({"type": "spherical", )" + origin + "}";
        break;
      default:
        joint = R"({"type": "free", )" + origin + "}";
        break;
    }
    out += (b ? "," : "") + body("b" + std::to_string(b), parent, joint, 0.5 + 0.1 * b);
  }
  return out + "]}";
}

// The mixed tree with couplings among its one-coordinate joints (revolute, prismatic, helical),
// each after the first coupled to the one before it, alternately linearly and by a polynomial
// law: θ and q then differ in layout as well as in value (a quaternion before a coupled joint).
std::string coupled_mixed_tree_json(unsigned seed, int bodies) {
  nlohmann::json m = nlohmann::json::parse(mixed_tree_json(seed, bodies));
  std::vector<std::string> one;
  for (const auto& b : m["bodies"])
    if (const std::string t = b["joint"]["type"];
        t == "revolute" || t == "prismatic" || t == "helical")
      one.push_back(b["name"]);
  m["couplings"] = nlohmann::json::array();
  for (std::size_t k = 1; k < one.size(); k += 2)
    if (k % 4 == 1)
      m["couplings"].push_back(
          {{"joint", one[k]}, {"follows", one[k - 1]}, {"ratio", 0.7}, {"offset", 0.1}});
    else
      m["couplings"].push_back({{"joint", one[k]},
                                {"follows", one[k - 1]},
                                {"polynomial", {{0.1, 0}, {0.6, 1}, {0.2, 2}}}});
  return m.dump();
}

}  // namespace

TEST_CASE("each new joint type alone matches its Simbody mobilizer", "[validation][joints]") {
  for (const auto& [label, joint] : kJoints) {
    const Model m = load_text(alone_json(joint));
    require_pass(validation::validate(m, quick(8, 0.2)), label);
  }
}

TEST_CASE("every joint type in one tree matches Simbody", "[validation][joints]") {
  const Model m = load_text(all_joints_json());
  REQUIRE(m.n_q() != m.n());
  require_pass(validation::validate(m, quick(10, 0.2)), "all joints");
}

TEST_CASE("seeded random trees of mixed joint types match Simbody", "[validation][joints]") {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    const int bodies = 3 + static_cast<int>(seed * 3);
    const Model m = load_text(mixed_tree_json(seed, bodies));
    require_pass(validation::validate(m, quick(5, 0.1)),
                 "seed " + std::to_string(seed) + ", " + std::to_string(bodies) + " bodies");
  }
}

TEST_CASE("random mixed trees with linear and law couplings beside quaternions match Simbody",
          "[validation][joints][couplings]") {
  int linear = 0, laws = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const int bodies = 6 + static_cast<int>(seed * 2);
    for (const bool with_laws : {false, true}) {
      std::string text = coupled_mixed_tree_json(seed, bodies);
      if (!with_laws) {  // the same couplings, every one linear
        nlohmann::json j = nlohmann::json::parse(text);
        for (auto& c : j["couplings"])
          if (c.contains("polynomial")) c.erase("polynomial"), c["ratio"] = -0.5;
        text = j.dump();
      }
      const Model m = load_text(text);
      if (m.n() == m.n_theta()) continue;  // no coupling drawn
      REQUIRE(m.n_q() != m.n());
      ++(m.coupling_level ? laws : linear);
      require_pass(validation::validate(m, quick(4, 0.1)),
                   "seed " + std::to_string(seed) + (with_laws ? ", laws" : ", linear"));
    }
  }
  CHECK(linear >= 3);
  CHECK(laws >= 3);
}

TEST_CASE("femdyn validate passes on a model of every joint type", "[validation][joints][cli]") {
  Scratch dir("validate_all_joints");
  std::ofstream(dir / "all_joints.json") << all_joints_json();
  const Run r = run("validate " + (dir / "all_joints.json") + " --states 5 --t-end 0.1");
  INFO(r.out);
  CHECK(r.code == 0);
  CHECK(r.out.find("FAIL") == std::string::npos);
}

TEST_CASE("a twin built with a wrong joint parameter does not match", "[validation][joints]") {
  // The twin as validate builds it, then one parameter of one mobilizer off by a little:
  // M^s (or h) must differ from femdyn's far beyond the tolerance (1e-10).
  const Model m = load_text(all_joints_json());
  Workspace ws(m);
  std::mt19937 rng(3);
  const VecX q = random_posture(m, rng);
  const VecX qd = VecX::Random(m.n()), tau = VecX::Zero(m.n());
  evaluate(m, ws, q, qd, tau);
  const auto error = [&](const std::function<void(validation::TwinModel&)>& change) {
    validation::TwinModel tm = validation::twin_model(m);
    change(tm);
    validation::SimbodyTwin twin(tm);
    const validation::TwinEquations s = twin.equations(q, qd, tau);
    return std::max(rel_error(ws.Ms, s.M), rel_error(ws.h, s.h));
  };
  CHECK(error([](validation::TwinModel&) {}) < 1e-10);
  const auto named = [&](validation::TwinModel & tm, const std::string& name) -> auto& {
    for (auto& b : tm.bodies)
      if (b.name == name) return b;
    FAIL("no body " << name);
    return tm.bodies[0];
  };
  CHECK(error([&](validation::TwinModel& tm) { named(tm, "screw").scalars.at("pitch") *= 1.01; }) >
        1e-6);
  CHECK(error([&](validation::TwinModel& tm) {
          auto& b = named(tm, "cardan");
          b.axis2 = -b.axis2;
        }) > 1e-4);
  CHECK(error([&](validation::TwinModel& tm) {
          auto& b = named(tm, "slider");
          b.axis2 = b.axis.cross(b.axis2);  // e₁ and e₂ exchanged
        }) > 1e-4);
  CHECK(error([&](validation::TwinModel& tm) {
          named(tm, "ball").R_pj =
              Mat3(Eigen::AngleAxisd(0.01, Vec3::UnitX())) * named(tm, "ball").R_pj;
        }) > 1e-4);
}
