#include "io/mesh.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "core/model/errors.hpp"
#include "io/input_file.hpp"

namespace femdyn {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw ModelError(path, what);
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

float little_endian_float(const char* p) {
  std::uint32_t u = 0;
  for (int k = 3; k >= 0; --k) u = (u << 8) | static_cast<unsigned char>(p[k]);
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

// Binary STL: an 80-byte header, a uint32 count n, then n records of 50 bytes (normal, three
// vertices as float32, two attribute bytes). Its size says it is binary, even when the header
// begins with "solid" as many exporters write.
bool is_binary_stl(const std::string& bytes) {
  if (bytes.size() < 84) return false;
  std::uint32_t n = 0;
  for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + k]);
  return bytes.size() == 84 + 50ull * n;
}

TriangleMesh binary_stl(const std::string& bytes) {
  TriangleMesh mesh;
  const std::size_t n = (bytes.size() - 84) / 50;
  mesh.vertices.reserve(3 * n);
  mesh.triangles.reserve(n);
  for (std::size_t f = 0; f < n; ++f) {
    const char* record = bytes.data() + 84 + 50 * f + 12;  // past the normal
    for (int k = 0; k < 3; ++k)
      mesh.vertices.emplace_back(little_endian_float(record + 12 * k),
                                 little_endian_float(record + 12 * k + 4),
                                 little_endian_float(record + 12 * k + 8));
    const auto i = static_cast<std::uint32_t>(3 * f);
    mesh.triangles.push_back({i, i + 1, i + 2});
  }
  return mesh;
}

// The three numbers after a text mesh's vertex keyword ("vertex" in STL, "v" in OBJ).
Vec3 vertex(std::istringstream& words, const std::string& path, int line_no) {
  Vec3 v;
  if (!(words >> v[0] >> v[1] >> v[2]))
    fail(path, "line " + std::to_string(line_no) + ": a vertex needs three numbers");
  return v;
}

// ASCII STL: "solid … facet normal … outer loop vertex x y z (×3) endloop endfacet … endsolid".
TriangleMesh ascii_stl(const std::string& path, const std::string& text) {
  TriangleMesh mesh;
  std::istringstream lines(text);
  std::string line;
  int line_no = 0, in_facet = 0;
  while (std::getline(lines, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string word;
    if (!(words >> word)) continue;
    if (word == "vertex") {
      mesh.vertices.push_back(vertex(words, path, line_no));
      ++in_facet;
    } else if (word == "endloop") {
      if (in_facet != 3)
        fail(path, "line " + std::to_string(line_no) + ": a facet has " + std::to_string(in_facet) +
                       " vertices, not 3");
      const auto i = static_cast<std::uint32_t>(mesh.vertices.size() - 3);
      mesh.triangles.push_back({i, i + 1, i + 2});
      in_facet = 0;
    }
  }
  if (in_facet) fail(path, "ends inside a facet (truncated)");
  return mesh;
}

// The vertex an OBJ face names ("7", "7/1", "7//3", "-1": 1-based, negative counting back).
std::uint32_t obj_index(const std::string& path, int line_no, const std::string& word,
                        std::size_t n_vertices) {
  long long i = 0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), i);
  if (ec != std::errc() || (end != word.data() + word.size() && *end != '/'))
    fail(path, "line " + std::to_string(line_no) + ": bad face index '" + word + "'");
  const long long n = static_cast<long long>(n_vertices);
  const long long k = i < 0 ? n + i : i - 1;
  if (i == 0 || k < 0 || k >= n)
    fail(path, "line " + std::to_string(line_no) + ": face index " + std::to_string(i) +
                   " out of range (" + std::to_string(n) + " vertices so far)");
  return static_cast<std::uint32_t>(k);
}

// Wavefront OBJ: "v x y z [w]" and "f i j k …" (a polygon becomes a fan of triangles); texture
// coordinates, normals, groups and materials do not change the solid and are skipped.
TriangleMesh obj(const std::string& path, const std::string& text) {
  TriangleMesh mesh;
  std::istringstream lines(text);
  std::string line;
  int line_no = 0;
  std::vector<std::uint32_t> face;
  while (std::getline(lines, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string word;
    if (!(words >> word)) continue;
    if (word == "v") {
      mesh.vertices.push_back(vertex(words, path, line_no));
    } else if (word == "f") {
      face.clear();
      while (words >> word) face.push_back(obj_index(path, line_no, word, mesh.vertices.size()));
      if (face.size() < 3)
        fail(path, "line " + std::to_string(line_no) + ": a face needs three vertices");
      for (std::size_t k = 1; k + 1 < face.size(); ++k)
        mesh.triangles.push_back({face[0], face[k], face[k + 1]});
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh read_mesh(const std::string& path, const Vec3& scale) {
  const std::string ext = lower_extension(path);
  if (ext != ".stl" && ext != ".obj")
    fail(path, "a mesh femdyn does not read (" + (ext.empty() ? std::string("no extension") : ext) +
                   "): femdyn reads STL and OBJ meshes");
  const std::string bytes = read_input_file(path);
  TriangleMesh mesh = ext == ".obj"          ? obj(path, bytes)
                      : is_binary_stl(bytes) ? binary_stl(bytes)
                                             : ascii_stl(path, bytes);
  if (mesh.triangles.empty()) fail(path, "a mesh with no triangle");
  for (Vec3& v : mesh.vertices) {
    if (!v.allFinite()) fail(path, "a vertex that is NaN or infinite");
    v = v.cwiseProduct(scale);
  }
  return mesh;
}

CentroidalMass solid_mass(const TriangleMesh& mesh, double density, double* volume) {
  // Tetrahedra from o, the vertices' mean: near the mesh, so that the sums do not cancel however
  // far the mesh is from its frame's origin.
  Vec3 o = Vec3::Zero();
  for (const Vec3& v : mesh.vertices) o += v;
  o /= static_cast<double>(std::max<std::size_t>(mesh.vertices.size(), 1));
  double V = 0;
  Vec3 first = Vec3::Zero();   // Σ V_f s_f / 4, about o
  Mat3 second = Mat3::Zero();  // ∫ r rᵀ dV about o
  for (const auto& t : mesh.triangles) {
    const Vec3 a = mesh.vertices[t[0]] - o, b = mesh.vertices[t[1]] - o,
               c = mesh.vertices[t[2]] - o;
    const double Vf = a.dot(b.cross(c)) / 6;
    const Vec3 s = a + b + c;
    V += Vf;
    first += Vf * s / 4;
    second +=
        Vf / 20 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  if (V < 0) {  // wound inside out
    V = -V;
    first = -first;
    second = -second;
  }
  if (volume) *volume = V;
  if (!(V > 0)) return {};
  const Vec3 c = first / V;  // the centre, from o
  const Mat3 about_com = density * (second - V * c * c.transpose());
  return {density * V, o + c, about_com.trace() * Mat3::Identity() - about_com};
}

}  // namespace femdyn
