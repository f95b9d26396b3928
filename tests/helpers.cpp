#include "tests/helpers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "compile/compile.hpp"
#include "models/random_tree.hpp"

namespace femdyn::test {
using Json = nlohmann::json;

std::string model_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/models/" + name;
}

std::vector<std::string> bundled_models() {
  std::vector<std::string> out;
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(FEMDYN_SOURCE_DIR) + "/models"))
    if (e.path().extension() == ".json") out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Model load_text(const std::string& json_text, const CompileOptions& options) {
  return compile(parse_spec(json_text, "test"), options);
}

std::string text_error(const std::string& json_text) {
  try {
    load_text(json_text);
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(loaded)";
}

std::string planar_chain(int n) {
  using nlohmann::json;
  json bodies = json::array();
  for (int i = 0; i < n; ++i)
    bodies.push_back(
        {{"name", "b" + std::to_string(i)},
         {"parent", i == 0 ? std::string("world") : "b" + std::to_string(i - 1)},
         {"joint", {{"type", "revolute"}, {"axis", {0, 0, 1}}, {"origin", {{"xyz", {0.1, 0, 0}}}}}},
         {"elements", {{{"type", "lumped_point"}, {"node", {0.1, 0, 0}}, {"mass", 1}}}}});
  return json{{"name", "chain"}, {"gravity", {0, -9.81, 0}}, {"bodies", bodies}}.dump();
}

std::string arm_json(double k, double c, double g) {
  std::ostringstream s;
  s.precision(17);
  s << R"({"name": "arm", "gravity": [0, 0, )" << -g << R"(], "bodies": [{"name": "arm",
    "parent": "world", "joint": {"name": "theta", "type": "revolute", "axis": [0, 1, 0],
    "spring": {"stiffness": )"
    << k << R"(}, "damping": )" << c << R"(}, "elements": [{"type": "lumped_point",
    "node": [1, 0, 0], "mass": 1.0}]}]})";
  return s.str();
}

std::string mixed_tree_json(unsigned seed, int bodies, double branching, bool couplings,
                            bool several_rates) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.2, 1.0);
  const auto v3 = [&](double s) { return Json::array({s * u(rng), s * u(rng), s * u(rng)}); };
  Json list = Json::array(), loads = Json::array(), coupled = Json::array();
  std::vector<int> movable;
  for (int b = 0; b < bodies; ++b) {
    int parent = b - 1;
    if (b > 1 && pos(rng) < 0.2 + 0.8 * branching) parent = static_cast<int>(rng() % b);
    const int kind = static_cast<int>(rng() % 8);
    Json joint = {{"name", "j" + std::to_string(b)},
                  {"origin", {{"xyz", v3(0.4)}, {"rpy", v3(2.0)}}}};
    if (several_rates && (kind >= 4 || (b == 0 && seed % 2))) {
      static constexpr const char* kTypes[] = {"universal", "planar", "spherical", "free"};
      joint["type"] = b == 0 && seed % 2 ? "free" : kTypes[kind - 4];
      if (joint["type"] == "universal") {
        joint["axis"] = {1, 0, 0};
        joint["axis2"] = {0, 0.6, 0.8};
      }
      if (joint["type"] == "planar") joint["axis"] = v3(1.0);
      movable.push_back(b);
    } else if (kind == 0 && b > 0) {
      joint["type"] = "fixed";
    } else {
      joint["type"] = kind == 1 ? "prismatic" : "revolute";
      joint["axis"] = v3(1.0);
      if (kind == 2) joint["spring"] = {{"stiffness", 3 * pos(rng)}, {"rest", u(rng)}};
      if (kind == 3) joint["damping"] = pos(rng);
      movable.push_back(b);
    }
    Json elements = Json::array();
    const double mass = pos(rng);
    elements.push_back({{"type", "lumped_point"}, {"node", v3(0.3)}, {"mass", mass}});
    if (rng() % 2)
      elements.push_back(
          {{"type", "rotary_node"},
           {"node", v3(0.3)},
           {"inertia", {{"ixx", 0.02}, {"iyy", 0.03}, {"izz", 0.04}, {"ixy", 0.004}}}});
    if (rng() % 2)
      elements.push_back({{"type", "space_bar"},
                          {"nodes", {v3(0.2), v3(0.5)}},
                          {"density", 2700},
                          {"area", 2e-4},
                          {"Iy", 2e-9},
                          {"Iz", 3e-9}});
    else
      elements.push_back(
          {{"type", "rigid_body"},
           {"mass", mass},
           {"com", v3(0.2)},
           {"inertia", {{"ixx", 0.05}, {"iyy", 0.06}, {"izz", 0.07}, {"iyz", -0.01}}}});
    list.push_back({{"name", "b" + std::to_string(b)},
                    {"parent", parent < 0 ? std::string("world") : "b" + std::to_string(parent)},
                    {"joint", joint},
                    {"elements", elements}});
    if (rng() % 4 == 0)
      loads.push_back({{"body", "b" + std::to_string(b)},
                       {"point", v3(0.3)},
                       {"force", v3(2.0)},
                       {"torque", v3(0.5)}});
  }
  // Couplings: about one movable joint in five follows an earlier one (or two).
  if (couplings)
    for (std::size_t k = 2; k < movable.size(); k += 5) {
      const std::string a = "j" + std::to_string(movable[k - 1]),
                        c = "j" + std::to_string(movable[k - 2]);
      coupled.push_back(
          {{"joint", "j" + std::to_string(movable[k])},
           {"follows", {{{"joint", a}, {"ratio", u(rng)}}, {{"joint", c}, {"ratio", u(rng)}}}},
           {"offset", 0.1 * u(rng)}});
    }
  return Json{{"name", "mixed tree " + std::to_string(seed)},
              {"gravity", {0.3, -0.2, -9.81}},
              {"bodies", list},
              {"loads", loads},
              {"couplings", coupled}}
      .dump();
}

std::string random_tree_json(unsigned seed, int bodies, double branching, bool prismatic,
                             double gravity) {
  // The random_tree model plugin (models/random_tree.hpp), with a gravity off the axes.
  const Json doc = {
      {"model", "random_tree"},
      {"params",
       {{"seed", seed}, {"bodies", bodies}, {"branching", branching}, {"prismatic", prismatic}}},
      {"gravity", {0.1, -0.2, -gravity}}};
  return doc.dump();
}

Run run_shell(const std::string& command) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  if (!p) throw std::runtime_error("popen failed: " + command);
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int status = pclose(p);
  return {WEXITSTATUS(status), out};
}

Run run(const std::string& args) { return run_shell(std::string(FEMDYN_BINARY) + " " + args); }

std::string nonlinear_coupled_tree_json(unsigned seed) {
  const Json params = {{"seed", seed}, {"bodies", 6}, {"branching", 0.3}, {"prismatic", true}};
  Json doc = random_tree(Params(params, "random_tree: "));  // the plugin's plain document
  doc["gravity"] = {0.1, -0.2, -9.81};
  doc["couplings"] = nlohmann::json::parse(R"([
    {"joint": "j2", "follows": "j1", "four_bar": {"ground": 3, "input": 1, "coupler": 3.5,
     "output": 2, "branch": 1, "input_offset": 0.4, "output_offset": 1.2}},
    {"joint": "j4", "follows": ["j0", "j3"],
     "polynomial": [[0.3, 1, 0], [0.2, 1, 1], [-0.1, 0, 2], [0.05, 2, 0], [0.1, 0, 0]]},
    {"joint": "j5", "follows": "j2",
     "spline": [[-3, -1], [-1, 0.2], [0, 0], [1, 0.7], [3, 1.2]]}])");
  return doc.dump();
}

double rel_error(const MatX& a, const MatX& b, double floor) { return relative_error(a, b, floor); }

double translation_value(const Model& m, const Workspace& ws, int i) {
  const SystemDof& d = m.dofs[i];
  const SystemNode& n = m.nodes[d.carrier];
  const BodyState& B = ws.body[n.body];
  return (ws.origin + (B.p + B.R * n.r))[d.axis];
}

std::string with_rods(const std::string& text, unsigned seed, int& rods) {
  nlohmann::json j = nlohmann::json::parse(text);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const auto v3 = [&] { return nlohmann::json::array({u(rng), u(rng), u(rng)}); };
  std::map<std::string, nlohmann::json*> by_name;
  for (nlohmann::json& b : j["bodies"]) by_name[b["name"]] = &b;
  for (nlohmann::json& b : j["bodies"]) {
    if (b["joint"]["type"] != "fixed" || b["parent"] == "world") continue;
    nlohmann::json& parent = *by_name.at(b["parent"]);
    parent["nodes"]["rod_end"] = v3();
    b["nodes"]["rod_start"] = v3();
    b["elements"].push_back({{"type", "rod"},
                             {"nodes", {"rod_start", b["parent"].get<std::string>() + "/rod_end"}},
                             {"mass", 0.3}});
    ++rods;
  }
  return j.dump();
}

}  // namespace femdyn::test
