// The MJCF reader's own pieces, shared by its files (io/mjcf_loader.cpp reads the tree and the
// joints, io/mjcf_bodies.cpp the bodies' mass, io/mjcf_equality.cpp the equalities). Not an
// interface of femdyn.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "io/centroidal_mass.hpp"
#include "io/mesh.hpp"
#include "io/mjcf_document.hpp"
#include "io/mjcf_geometry.hpp"
#include "io/mjcf_loader.hpp"

namespace femdyn::mjcf {

// A MuJoCo body as femdyn holds it: the femdyn body carrying its mass (the last of its chain),
// that body's frame in the MuJoCo body's frame (a shift by the last joint's pos), and the
// MuJoCo body's pose in the world in the model as written (qpos0).
struct PlacedBody {
  std::string femdyn;
  Vec3 shift = Vec3::Zero();
  Pose world0;
};

// The MuJoCo joints by name, for the equalities: the femdyn joint's name, the MuJoCo type and
// `ref` (rad or m).
struct PlacedJoint {
  std::string femdyn_joint, type;
  double ref = 0;
};

struct Tree {
  std::map<std::string, PlacedBody> bodies;   // by MuJoCo name ("world" included)
  std::map<std::string, PlacedJoint> joints;  // by MuJoCo name
};

// The meshes that gave mass, and those whose legacy solid is not theirs (mjcf_loader.hpp).
using MassNotes = MjcfMassNotes;

// A body's mass properties in its own frame, as MuJoCo's compiler makes them (before
// settotalmass, which scales every body).
CentroidalMass body_mass(const Document& doc, const XMLElement& body, const std::string& childclass,
                         MassNotes& meshes);

// The body's rigid_body element (its frame shifted by `shift`), or null without mass; a
// non-physical inertia balanced when asked, each change in `notes`.
Json mass_element(const Document& doc, const XMLElement& body, const CentroidalMass& mass,
                  const Vec3& shift, const MjcfOptions& options, std::vector<std::string>& notes);

// <equality>: constraints and couplings added to the model document.
void read_equalities(const Document& doc, const Tree& tree, Json& model,
                     std::vector<std::string>& notes);

// The <mesh> asset a mesh geom names (its class, scale and file, meshdir-relative; no file for
// an inline mesh; `source` names it in messages), without reading it; or a one-line refusal
// naming the geom.
struct MeshFile {
  const XMLElement* asset = nullptr;
  std::string cls, source, file;
  Vec3 scale = Vec3::Ones();
};
MeshFile mesh_file_of(const Document& doc, const XMLElement& geom, const std::string& cls);

// A mesh geom's mass in the body frame: the solid the mesh bounds, as MuJoCo's compiler computes
// it (legacy |V| tetrahedra, or signed ones with exactmeshinertia; io/mesh.hpp), m = the geom's
// mass or ρV, placed at the geom's pose; counted in `meshes`.
CentroidalMass mesh_geom_mass(const Document& doc, const XMLElement& geom, const std::string& cls,
                              MassNotes& meshes);

// The geoms of `body` (or the world) MuJoCo's viewer draws by default (groups 0 to 2; no plane
// or height field), in the frame `frame` places the body's frame in, on femdyn body `link`.
void add_visuals(const Document& doc, const XMLElement& body, const std::string& childclass,
                 const std::string& link, const Pose& frame, std::vector<Visual>& out);

// A rotation's roll, pitch, yaw (R = Rz(y) Ry(p) Rx(r)).
Vec3 rotation_rpy(const Mat3& R);

}  // namespace femdyn::mjcf
