// Mesh geoms' mass as MuJoCo's compiler computes it (mjcf_reading.hpp: mesh_of, mesh_geom_mass).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "io/convex_hull.hpp"
#include "io/mjcf_reading.hpp"

namespace femdyn::mjcf {
namespace {

const XMLElement* mesh_asset(const Document& doc, const std::string& name) {
  for (const XMLElement* asset : doc.sections("asset"))
    for (const XMLElement* mesh : doc.children(*asset, "mesh")) {
      if (const char* own = mesh->Attribute("name")) {
        if (name == own) return mesh;
      } else if (const char* file = mesh->Attribute("file");
                 file && std::filesystem::path(file).stem().string() == name) {
        return mesh;  // unnamed: its file's name without folder and extension
      }
    }
  return nullptr;
}

// The convex hull of a mesh's vertices, or the one line saying why it has none.
TriangleMesh hull_of(const Document& doc, const XMLElement& mesh, const std::vector<Vec3>& points) {
  try {
    return convex_hull(points, "the vertices");
  } catch (const Error& e) {
    doc.fail(mesh, e.what());
  }
}

// vertex="x y z …" face="i j k …"; without faces, the vertices' convex hull (as MuJoCo).
TriangleMesh inline_mesh(const Document& doc, const XMLElement& mesh, const std::string& cls) {
  const std::vector<double> v = doc.numbers(mesh, "vertex", cls, -1);
  const std::vector<double> f = doc.numbers(mesh, "face", cls, -1);
  if (v.size() % 3 || f.size() % 3) doc.fail(mesh, "vertex and face need triples of numbers");
  TriangleMesh out;
  for (std::size_t k = 0; k < v.size(); k += 3) out.vertices.emplace_back(v[k], v[k + 1], v[k + 2]);
  if (f.empty()) return hull_of(doc, mesh, out.vertices);
  for (std::size_t k = 0; k < f.size(); k += 3) {
    std::array<std::uint32_t, 3> t{};
    for (int i = 0; i < 3; ++i) {
      const double x = f[k + i];
      if (x < 0 || x >= static_cast<double>(out.vertices.size()) || x != std::floor(x))
        doc.fail(mesh, "face: index " + std::to_string(x) + " is not a vertex");
      t[i] = static_cast<std::uint32_t>(x);
    }
    out.triangles.push_back(t);
  }
  return out;
}

// MuJoCo's legacy mesh inertia (its default unless exactmeshinertia): tetrahedra from the
// faces' area-weighted centroid, then from the centre found, each volume taken positive.
// Equal to solid_mass for a convex mesh; it counts a non-convex one's folds twice.
CentroidalMass legacy_solid_mass(const TriangleMesh& mesh, double density, double& volume) {
  const auto corner = [&](const auto& t, int k) -> const Vec3& { return mesh.vertices[t[k]]; };
  Vec3 face_centre = Vec3::Zero();
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const double a = (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0)).norm() / 2;
    face_centre += a * (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3;
    area += a;
  }
  if (!(area > 0)) return {};
  face_centre /= area;
  const auto tetra = [&](const auto& t, const Vec3& apex) {  // |V| of apex and the face
    return std::abs((corner(t, 0) - apex).dot((corner(t, 1) - apex).cross(corner(t, 2) - apex))) /
           6;
  };
  double V = 0;
  Vec3 com = Vec3::Zero();
  for (const auto& t : mesh.triangles) {
    const double Vf = tetra(t, face_centre);
    V += Vf;
    com += Vf * (3.0 / 4 * (corner(t, 0) + corner(t, 1) + corner(t, 2)) / 3 + face_centre / 4);
  }
  if (!(V > 0)) return {};
  com /= V;
  volume = 0;
  Mat3 second = Mat3::Zero();  // ∫ r rᵀ dV about com
  for (const auto& t : mesh.triangles) {
    const double Vf = tetra(t, com);
    const Vec3 a = corner(t, 0) - com, b = corner(t, 1) - com, c = corner(t, 2) - com,
               s = a + b + c;
    volume += Vf;
    second +=
        Vf / 20 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  second *= density;
  return {density * volume, com, second.trace() * Mat3::Identity() - second};
}

// The triangles of the mesh a geom names (its file or inline vertex/face), scaled, after the
// asset's unread attributes are refused.
TriangleMesh mesh_of(const Document& doc, const XMLElement& geom, const std::string& cls,
                     const MeshFile& f) {
  for (const char* unsupported : {"refpos", "refquat"})
    if (f.asset->Attribute(unsupported))
      doc.fail(*f.asset, std::string(unsupported) + " is not read by femdyn (MuJoCo removed it)");
  const char* inertia = doc.attr(*f.asset, "inertia", f.cls);
  if (inertia && std::strcmp(inertia, "legacy") && std::strcmp(inertia, "exact") &&
      std::strcmp(inertia, "convex"))
    doc.fail(*f.asset, std::string("inertia=\"") + inertia +
                           "\": femdyn computes a mesh's legacy, exact or convex volume inertia");
  TriangleMesh out;
  if (!f.file.empty()) {
    try {
      out = read_mesh(f.file, f.scale);
    } catch (const Error& e) {
      doc.fail(geom, "mesh " + quoted_text(doc.attr(geom, "mesh", cls)) + ": " + e.what());
    }
  } else {
    out = inline_mesh(doc, *f.asset, f.cls);
    for (Vec3& v : out.vertices) v = v.cwiseProduct(f.scale);
  }
  if (inertia && !std::strcmp(inertia, "convex")) return hull_of(doc, *f.asset, out.vertices);
  return out;
}

}  // namespace

MeshFile mesh_file_of(const Document& doc, const XMLElement& geom, const std::string& cls) {
  const char* name = doc.attr(geom, "mesh", cls);
  if (!name) doc.fail(geom, "a mesh geom names no mesh");
  const XMLElement* asset = mesh_asset(doc, name);
  if (!asset) doc.fail(geom, "mesh " + quoted_text(name) + " is not an <asset> <mesh>");
  MeshFile out{asset, doc.class_of(*asset, "")};
  out.scale = doc.vec3(*asset, "scale", out.cls, Vec3::Ones());
  out.source = quoted_text(name);
  if (const char* file = asset->Attribute("file")) {
    const std::filesystem::path p(file);
    out.file = (p.is_absolute() ? p : std::filesystem::path(doc.compiler().meshdir) / p).string();
    out.source += " (file " + quoted_text(file) + ")";
  }
  return out;
}

CentroidalMass mesh_geom_mass(const Document& doc, const XMLElement& geom, const std::string& cls,
                              MassNotes& meshes) {
  if (doc.flag(geom, "shellinertia", cls, false))
    doc.fail(geom, "shellinertia: femdyn computes a mesh's volume inertia, not its shell's");
  const MeshFile file = mesh_file_of(doc, geom, cls);
  const TriangleMesh mesh = mesh_of(doc, geom, cls, file);
  const char* inertia = doc.attr(*file.asset, "inertia", file.cls);
  const bool exact = doc.compiler().every_mesh_exact ||
                     (inertia ? !std::strcmp(inertia, "exact") : doc.compiler().exact_mesh_inertia);
  double V = 0, V_solid = 0;
  const CentroidalMass solid_unit = solid_mass(mesh, 1, &V_solid);
  const CentroidalMass unit = exact ? solid_unit : legacy_solid_mass(mesh, 1, V);
  if (exact) V = V_solid;
  if (!(V > 1e-15))
    doc.fail(geom, "mesh " + file.source + " bounds no volume (an open or flat mesh)");
  ++meshes.mesh_geoms;
  if (!exact && std::abs(V - V_solid) > 1e-9 * V) {
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.3g", V / V_solid);
    meshes.not_solid.push_back(file.source + " (×" + ratio + ")");
  }
  const std::vector<double> given = doc.numbers(geom, "mass", cls, 1);
  const double density = given.empty() ? doc.number(geom, "density", cls, 1000) : given[0] / V;
  if (density < 0) doc.fail(geom, "a negative mass or density");
  const Pose pose = pose_of(doc, geom, cls);
  const CentroidalMass solid{density * unit.mass, unit.com, density * unit.inertia};
  return solid.expressed_in(pose.R, pose.p);
}

}  // namespace femdyn::mjcf
