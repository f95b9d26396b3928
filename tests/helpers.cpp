#include "tests/helpers.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace femdyn::test {

std::string model_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/models/" + name;
}

std::vector<std::string> bundled_models() {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(std::string(FEMDYN_SOURCE_DIR) + "/models"))
    if (e.path().extension() == ".json") out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

Model load_text(const std::string& json_text) { return compile(parse_spec(json_text, "test")); }

namespace {

std::string vec(double a, double b, double c) {
  std::ostringstream o;
  o.precision(17);
  o << "[" << a << ", " << b << ", " << c << "]";
  return o.str();
}

}  // namespace

std::string random_tree_json(unsigned seed, int bodies, double branching, bool prismatic,
                             double gravity) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.2, 1.0);
  std::ostringstream o;
  o.precision(17);
  o << "{\"name\": \"random tree " << seed << "\", \"gravity\": " << vec(0.1, -0.2, -gravity)
    << ", \"bodies\": [";
  for (int b = 0; b < bodies; ++b) {
    int parent = b - 1;
    if (b > 1 && pos(rng) < 0.2 + 0.8 * branching) parent = static_cast<int>(rng() % b);
    const bool slide = prismatic && (rng() % 4 == 0);
    // Physical inertia: principal moments from three positive "second moments" a, b, c.
    const double sa = pos(rng), sb = pos(rng), sc = pos(rng), mass = pos(rng);
    Eigen::Vector3d principal(sb + sc, sa + sc, sa + sb);
    const Eigen::Matrix3d R = rpy_to_rotation(Eigen::Vector3d(u(rng), u(rng), u(rng)) * 3);
    const Eigen::Matrix3d I = 0.05 * mass * R * principal.asDiagonal() * R.transpose();
    o << (b ? ", " : "") << "{\"name\": \"b" << b << "\", \"parent\": \""
      << (parent < 0 ? std::string("world") : "b" + std::to_string(parent)) << "\", "
      << "\"joint\": {\"type\": \"" << (slide ? "prismatic" : "revolute") << "\", "
      << "\"axis\": " << vec(u(rng), u(rng), u(rng)) << ", \"origin\": {\"xyz\": "
      << vec(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng)) << ", \"rpy\": "
      << vec(u(rng), u(rng), u(rng)) << "}}, \"elements\": [{\"type\": \"rigid_body\", "
      << "\"mass\": " << mass << ", \"com\": " << vec(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng))
      << ", \"inertia\": [" << vec(I(0, 0), I(0, 1), I(0, 2)) << ", "
      << vec(I(1, 0), I(1, 1), I(1, 2)) << ", " << vec(I(2, 0), I(2, 1), I(2, 2)) << "]}]}";
  }
  o << "]}";
  return o.str();
}

VecX random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  VecX v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

double rel_error(const MatX& a, const MatX& b, double floor) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), floor);
}

double translation_value(const Model& m, const Workspace& ws, int i) {
  const SystemDof& d = m.dofs[i];
  const SystemNode& n = m.nodes[d.carrier];
  const BodyState& B = ws.body[n.body];
  return (B.p + B.R * n.r)[d.axis];
}

Mat3 body_rotation(const Workspace& ws, int body) { return ws.body[body].R; }

}  // namespace femdyn::test
