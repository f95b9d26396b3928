// The bodies' mass as MuJoCo's compiler makes it (mjcf_reading.hpp: body_mass, mass_element).
#include <Eigen/Eigenvalues>
#include <cstring>

#include "core/model/names.hpp"
#include "core/spatial/inertia.hpp"
#include "io/mjcf_reading.hpp"

namespace femdyn::mjcf {
namespace {

// <inertial pos orientation mass diaginertia | fullinertia="ixx iyy izz ixy ixz iyz">.
CentroidalMass inertial_mass(const Document& doc, const XMLElement& in, MassNotes& notes) {
  const double m = doc.number(in, "mass", "", -1);
  if (m < 0) doc.fail(in, "needs a mass ≥ 0");
  const std::vector<double> d = doc.numbers(in, "diaginertia", "", 3);
  const std::vector<double> f = doc.numbers(in, "fullinertia", "", 6);
  if (d.empty() == f.empty()) doc.fail(in, "needs one of diaginertia and fullinertia");
  Mat3 I;
  if (!d.empty()) {
    I = Vec3(d[0], d[1], d[2]).asDiagonal();
  } else {
    I << f[0], f[3], f[4], f[3], f[1], f[5], f[4], f[5], f[2];
    ++notes.full_inertias;
  }
  const Pose pose = pose_of(doc, in, "");
  if (!f.empty() && !pose.R.isIdentity(0))
    doc.fail(in, "fullinertia gives the axes itself: no orientation with it (as MuJoCo)");
  return {m, pose.p, pose.R * I * pose.R.transpose()};
}

// The geoms in inertiagrouprange, welded: a plane or height field adds nothing, a mesh the solid
// it bounds (io/mjcf_mesh.cpp).
CentroidalMass geoms_mass(const Document& doc, const XMLElement& body, const std::string& inherited,
                          MassNotes& meshes) {
  CentroidalMass sum;
  for (const XMLElement* geom : doc.children(body, "geom")) {
    const std::string cls = doc.class_of(*geom, inherited);
    const double group = doc.number(*geom, "group", cls, 0);
    if (group < doc.compiler().group_lo || group > doc.compiler().group_hi) continue;
    const char* type = doc.attr(*geom, "type", cls);
    if (type && (!std::strcmp(type, "plane") || !std::strcmp(type, "hfield"))) continue;
    if (type && !std::strcmp(type, "mesh")) {
      if (doc.number(*geom, "mass", cls, -1) == 0 ||
          (!doc.attr(*geom, "mass", cls) && doc.number(*geom, "density", cls, 1000) == 0))
        continue;
      sum = welded(sum, mesh_geom_mass(doc, *geom, cls, meshes));
      continue;
    }
    const GeomMass g = primitive_geom_mass(doc, *geom, cls);
    sum = welded(sum, {g.mass, g.pose.p, g.pose.R * g.I * g.pose.R.transpose()});
  }
  return sum;
}

// Principal moments and axes of I (ascending), to bound or balance them as MuJoCo does.
void principal_rebuild(CentroidalMass& mp, const auto& change) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(mp.inertia);
  Vec3 d = eig.eigenvalues();
  change(d);
  mp.inertia = eig.eigenvectors() * d.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace

CentroidalMass body_mass(const Document& doc, const XMLElement& body, const std::string& childclass,
                         MassNotes& meshes) {
  const Compiler& c = doc.compiler();
  const std::vector<const XMLElement*> inertial = doc.children(body, "inertial");
  if (inertial.size() > 1) doc.fail(body, "more than one <inertial>");
  CentroidalMass mp;
  if (c.inertia_from_geom == Compiler::FromGeom::always ||
      (c.inertia_from_geom == Compiler::FromGeom::automatic && inertial.empty()))
    mp = geoms_mass(doc, body, childclass, meshes);
  else if (!inertial.empty())
    mp = inertial_mass(doc, *inertial[0], meshes);
  if (c.boundmass > 0 && mp.mass < c.boundmass) mp.mass = c.boundmass;
  if (c.boundinertia > 0) principal_rebuild(mp, [&](Vec3& d) { d = d.cwiseMax(c.boundinertia); });
  if (c.balanceinertia)  // a principal moment beyond the other two's sum: all three their mean
    principal_rebuild(mp, [](Vec3& d) {
      if (d[0] + d[1] < d[2]) d.setConstant(d.sum() / 3);
    });
  return mp;
}

Json mass_element(const Document& doc, const XMLElement& body, const CentroidalMass& mass,
                  const Vec3& shift, const MjcfOptions& options, std::vector<std::string>& notes) {
  if (mass.empty()) return nullptr;
  Mat3 I = mass.inertia;
  const double L = std::max(1.0, (mass.com - shift).norm());
  if (const auto problem = inertia_problem(I, mass.mass * L * L)) {
    if (!options.balance_inertia)
      doc.fail(body, *problem +
                         "; the balance_inertia option (--balance-inertia) takes the "
                         "nearest physical inertia instead");
    const Mat3 balanced = nearest_physical_inertia(I);
    notes.push_back(doc.file_of(body) + ": " + doc.who(body) +
                    ": inertia balanced to the nearest physical one, principal moments " +
                    principal_moments_text(I) + " -> " + principal_moments_text(balanced));
    I = balanced;
  }
  I = nearest_physical_inertia(I);  // round-off within the check's tolerance
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(vec3_json(I.row(r).transpose()));
  const Vec3 com = mass.com - shift;
  if (mass.mass == 0) return {{"type", "rotary_node"}, {"node", vec3_json(com)}, {"inertia", rows}};
  return {{"type", "rigid_body"}, {"mass", mass.mass}, {"com", vec3_json(com)}, {"inertia", rows}};
}

}  // namespace femdyn::mjcf
