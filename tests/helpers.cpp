#include "tests/helpers.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "compile/compile.hpp"
#include "models/random_tree.hpp"

namespace femdyn::test {

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
  return (B.p + B.R * n.r)[d.axis];
}

}  // namespace femdyn::test
