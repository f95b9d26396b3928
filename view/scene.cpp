#include "view/scene.hpp"

#include <Eigen/Eigenvalues>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "core/dynamics/body_inertia.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/model/errors.hpp"
#include "core/model/joint_type.hpp"
#include "core/model/loop_constraint.hpp"
#include "core/workspace/workspace.hpp"
#include "io/input_file.hpp"
#include "io/mesh.hpp"

namespace femdyn::view {
namespace {

// Positions to the micrometre and unit quaternions to 1e-6: the page draws, it does not compute.
double rounded(double x) { return std::round(x * 1e6) / 1e6; }

Json vec_json(const Eigen::Ref<const VecX>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(rounded(v[i]));
  return out;
}

// [x, y, z, w], as three.js orders a quaternion.
Json quaternion_json(const Mat3& R) {
  const Eigen::Quaterniond q(R);
  return vec_json(Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()));
}

Json body_json(const Body& b) {
  const Joint& j = b.joint;
  return {{"name", b.name},
          {"parent", b.parent},
          {"joint",
           {{"name", j.name},
            {"type", std::string(joint_type_name(j.type))},
            {"dofs", j.nv},
            {"origin", vec_json(j.p_pj)},  // in the parent's frame
            {"axis", vec_json(j.axis)},    // in the body (joint) frame
            {"axis2", vec_json(j.axis2)}}}};
}

// Mass, centre of mass and principal inertia (moments and axes as columns, body frame).
Json element_json(const ElementEntry& e) {
  const MassProperties mp = e.element->mass_properties();
  const Eigen::SelfAdjointEigenSolver<Mat3> principal(mp.inertia_com());
  Json nodes = Json::array();
  const auto element_nodes = e.element->nodes();
  for (std::size_t l = 0; l < element_nodes.size(); ++l)
    nodes.push_back({{"body", e.node_body[l]},
                     {"label", l < e.node_labels.size() ? e.node_labels[l] : ""},
                     {"p", vec_json(element_nodes[l].position)}});
  return {{"type", std::string(e.element->type_name())},
          {"body", e.body},
          {"mass", mp.mass},
          {"com", vec_json(mp.com)},
          {"moments", vec_json(principal.eigenvalues())},
          {"axes", quaternion_json(principal.eigenvectors().determinant() < 0
                                       ? Mat3(-principal.eigenvectors())
                                       : Mat3(principal.eigenvectors()))},
          {"nodes", nodes}};
}

// Base64 of raw bytes (RFC 4648), for the meshes' arrays.
std::string base64(const void* data, std::size_t bytes) {
  static constexpr char digits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes; i += 3) {
    const unsigned x =
        (b[i] << 16) | (i + 1 < bytes ? b[i + 1] << 8 : 0) | (i + 2 < bytes ? b[i + 2] : 0);
    out += digits[(x >> 18) & 63];
    out += digits[(x >> 12) & 63];
    out += i + 1 < bytes ? digits[(x >> 6) & 63] : '=';
    out += i + 2 < bytes ? digits[x & 63] : '=';
  }
  return out;
}

// The meshes the visuals name, each file and scale read once, as base64 arrays the page turns
// into geometry: positions float32 x y z per vertex, indices uint32 per triangle corner. At most
// kMaxPageTriangles in all: a page stays one that a browser opens.
struct MeshTable {
  Json meshes = Json::array();
  std::vector<double> radius;  // each entry's largest distance of a vertex from its origin
  std::map<std::pair<std::string, std::string>, int> index;  // (path, scale) -> entry
  std::size_t triangles = 0, collada_bytes = 0;

  // The entry of v's mesh, or -1 with `why`.
  int entry(const Visual& v, std::string& why) {
    if (v.mesh_path.empty()) {
      why = v.mesh_issue.empty() ? "not found" : v.mesh_issue;
      return -1;
    }
    const std::pair<std::string, std::string> key{v.mesh_path, vec_json(v.size).dump()};
    if (const auto it = index.find(key); it != index.end()) return it->second;
    if (is_collada(v.mesh_path)) return collada(v, key, why);
    TriangleMesh mesh;
    try {
      mesh = read_mesh(v.mesh_path, v.size);
    } catch (const Error& e) {
      why = e.what();
      return -1;
    }
    if (triangles + mesh.triangles.size() > kMaxPageTriangles) {
      why = "over the page's budget of " + std::to_string(kMaxPageTriangles) + " triangles";
      return -1;
    }
    triangles += mesh.triangles.size();
    std::vector<float> xyz;
    xyz.reserve(3 * mesh.vertices.size());
    for (const Vec3& p : mesh.vertices)
      for (int k = 0; k < 3; ++k) xyz.push_back(static_cast<float>(p[k]));
    double r = 0;
    for (const Vec3& p : mesh.vertices) r = std::max(r, p.norm());
    radius.push_back(r);
    meshes.push_back({{"triangles", mesh.triangles.size()},
                      {"positions", base64(xyz.data(), xyz.size() * sizeof(float))},
                      {"indices", base64(mesh.triangles.data(),
                                         mesh.triangles.size() * sizeof(mesh.triangles[0]))}});
    return index[key] = static_cast<int>(meshes.size()) - 1;
  }

  static bool is_collada(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".dae";
  }

  // A Collada file goes in as its text, for three.js's Collada loader in the page (at most
  // kMaxPageColladaBytes in all); its scale is applied there.
  int collada(const Visual& v, const std::pair<std::string, std::string>& key, std::string& why) {
    std::string text;
    try {
      text = read_input_file(v.mesh_path);
    } catch (const Error& e) {
      why = e.what();
      return -1;
    }
    if (collada_bytes + text.size() > kMaxPageColladaBytes) {
      why = "over the page's budget of " + std::to_string(kMaxPageColladaBytes >> 20) +
            " MiB of Collada";
      return -1;
    }
    collada_bytes += text.size();
    radius.push_back(0);  // (its extent is known once the page's loader has read it)
    meshes.push_back({{"collada", std::move(text)}, {"scale", vec_json(v.size)}});
    return index[key] = static_cast<int>(meshes.size()) - 1;
  }
};

// A primitive's bounding sphere about its origin (Visual's sizes: box edges; cylinder and capsule
// radius and length; sphere radius; ellipsoid radii).
double bounding_radius(const std::string& shape, const Vec3& size) {
  if (shape == "box") return 0.5 * size.norm();
  if (shape == "cylinder") return std::hypot(size[0], 0.5 * size[1]);
  if (shape == "capsule") return size[0] + 0.5 * size[1];
  if (shape == "sphere") return size[0];
  return size.cwiseAbs().maxCoeff();  // ellipsoid
}

// A visual on the body its link is (or is welded into: a named frame), in that body's frame;
// on the world when the link is not in the model (a URDF's root welded to the world).
Json visual_json(const Model& m, const Visual& v, MeshTable& table, Json& not_drawn) {
  int body = -1;
  Mat3 R = v.R;
  Vec3 p = v.xyz;
  for (const Frame& f : m.frames)
    if (f.name == v.link) {
      body = f.body;
      R = f.R_BF * v.R;
      p = f.p_BF + f.R_BF * v.xyz;
      break;
    }
  Json out = {{"body", body},     {"link", v.link},
              {"shape", v.shape}, {"size", vec_json(v.size)},
              {"p", vec_json(p)}, {"quaternion", quaternion_json(R)}};
  if (v.shape == "invalid")
    not_drawn.push_back({{"link", v.link}, {"mesh", "<visual>"}, {"why", v.mesh_issue}});
  if (v.shape == "mesh") {
    std::string why;
    const int entry = table.entry(v, why);
    out["mesh"] = entry;
    out["file"] = v.mesh;
    if (entry >= 0) out["radius"] = rounded(table.radius[entry]);
    if (!why.empty()) not_drawn.push_back({{"link", v.link}, {"mesh", v.mesh}, {"why", why}});
  } else if (v.shape != "invalid") {
    out["radius"] = rounded(bounding_radius(v.shape, v.size));
  }
  if (v.rgba) out["rgba"] = vec_json(*v.rgba);
  return out;
}

// A body without visuals drawn as the box of its inertia: the same mass and principal moments
// (edges √(6 (I_j + I_k − I_i)/m)), at its centre of mass along its principal axes. A flexible
// bar's pieces are not: the bar is drawn along its centreline (bars_json).
Json inertia_boxes_json(const Model& m, const Json& visuals) {
  std::set<int> seen;  // the bodies visual_json placed visuals on, and the bars' pieces
  for (const Json& v : visuals) seen.insert(v["body"].get<int>());
  for (const BarCentreline& bar : m.bars) seen.insert(bar.stations.begin(), bar.stations.end());
  Json out = Json::array();
  const std::vector<MassProperties> mp = body_mass_properties(m);
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    if (seen.count(static_cast<int>(b)) || !(mp[b].mass > 0)) continue;
    const Eigen::SelfAdjointEigenSolver<Mat3> principal(mp[b].inertia_com());
    const Vec3 I = principal.eigenvalues();
    const Vec3 edges(std::sqrt(std::max(0.0, 6 * (I[1] + I[2] - I[0]) / mp[b].mass)),
                     std::sqrt(std::max(0.0, 6 * (I[0] + I[2] - I[1]) / mp[b].mass)),
                     std::sqrt(std::max(0.0, 6 * (I[0] + I[1] - I[2]) / mp[b].mass)));
    if (edges.maxCoeff() < 1e-9) continue;  // a point mass: its element marker shows it
    const Mat3 axes = principal.eigenvectors().determinant() < 0 ? Mat3(-principal.eigenvectors())
                                                                 : Mat3(principal.eigenvectors());
    out.push_back({{"body", b},
                   {"com", vec_json(mp[b].com)},
                   {"size", vec_json(edges)},
                   {"quaternion", quaternion_json(axes)}});
  }
  return out;
}

// Each flexible bar: the bodies whose origins lie on its centreline, from the clamp to the tip
// (the page draws a tube through them at every frame), and the section's radius.
Json bars_json(const Model& m) {
  Json out = Json::array();
  for (const BarCentreline& bar : m.bars)
    out.push_back({{"name", bar.name}, {"stations", bar.stations}, {"radius", bar.radius}});
  return out;
}

// Each loop constraint's two places (body, point in its frame; -1: the world).
Json constraints_json(const Model& m) {
  Json out = Json::array();
  for (const LoopConstraint& c : m.constraints) {
    if (c.type == ConstraintType::Gear) continue;  // between coordinates: no place to draw
    out.push_back({{"name", c.name},
                   {"type", constraint_type_name(c.type)},
                   {"a", {{"body", c.a.body}, {"p", vec_json(c.a.p)}}},
                   {"b", {{"body", c.b.body}, {"p", vec_json(c.b.p)}}}});
  }
  return out;
}

// Each body's pose at q, [x y z qx qy qz qw] body after body, from the model's kinematics.
Json poses_json(const Model& m, Workspace& ws, const VecX& q, double t) {
  propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = false, .bias = false, .rows = false});
  Json out = Json::array();
  for (const BodyState& B : ws.body) {
    if (!B.p.allFinite() || !B.R.allFinite())
      throw StateError("the pose at t = " + std::to_string(t) + " is NaN or Inf");
    for (const Json& x : vec_json(Vec3(ws.origin + B.p))) out.push_back(x);
    for (const Json& x : quaternion_json(B.R)) out.push_back(x);
  }
  return out;
}

Json motion_json(const Model& m, const Motion& motion) {
  Workspace ws(m);
  Json t = Json::array(), poses = Json::array(), q = Json::array(), kinetic = Json::array(),
       potential = Json::array(), work = Json::array();
  for (const MotionFrame& f : motion.frames) {
    t.push_back(f.t);
    poses.push_back(poses_json(m, ws, f.q, f.t));
    q.push_back(vec_json(f.q));
    kinetic.push_back(f.kinetic);
    potential.push_back(f.potential);
    work.push_back(f.work);
  }
  return {{"trajectory", motion.trajectory},
          {"t", t},
          {"poses", poses},
          {"q", q},
          {"energy",
           {{"source", motion.energy_source},
            {"kinetic", kinetic},
            {"potential", potential},
            {"work", work}}}};
}

}  // namespace

Json scene_json(const Model& m, const Motion& motion, const std::vector<Visual>& visuals,
                const std::string& source) {
  Json bodies = Json::array(), frames = Json::array(), elements = Json::array(),
       shapes = Json::array(), not_drawn = Json::array();
  for (const Body& b : m.bodies) bodies.push_back(body_json(b));
  for (std::size_t f = m.bodies.size(); f < m.frames.size(); ++f)
    frames.push_back({{"name", m.frames[f].name},
                      {"body", m.frames[f].body},
                      {"p", vec_json(m.frames[f].p_BF)},
                      {"quaternion", quaternion_json(m.frames[f].R_BF)}});
  for (const ElementEntry& e : m.elements) elements.push_back(element_json(e));
  MeshTable table;
  for (const Visual& v : visuals) shapes.push_back(visual_json(m, v, table, not_drawn));
  const Json boxes = inertia_boxes_json(m, shapes), constraints = constraints_json(m),
             bars = bars_json(m);
  int joints = 0;
  for (const Body& b : m.bodies) joints += b.joint.type != JointType::Fixed;
  return {{"model", m.name},
          {"source", source},
          {"gravity", vec_json(m.gravity)},
          {"coordinates", m.configuration_names},
          {"bodies", bodies},
          {"frames", frames},
          {"elements", elements},
          {"visuals", shapes},
          {"meshes", table.meshes},
          {"not_drawn", not_drawn},
          {"inertia_boxes", boxes},
          {"constraints", constraints},
          {"bars", bars},
          {"motion", motion_json(m, motion)},
          {"counts",
           {{"bodies", bodies.size()},
            {"joints", joints},
            {"elements", elements.size()},
            {"frames", frames.size()},
            {"visuals", shapes.size() - not_drawn.size()},
            {"meshes", table.meshes.size()},
            {"not_drawn", not_drawn.size()},
            {"inertia_boxes", boxes.size()},
            {"constraints", constraints.size()},
            {"bars", bars.size()},
            {"motion_frames", motion.frames.size()}}}};
}

}  // namespace femdyn::view
