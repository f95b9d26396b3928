// MJCF's frames and the mass of its primitive geoms, as MuJoCo's compiler computes them
// (io/mjcf_loader.cpp). Not an interface of femdyn.
//   Orientation (one of): quat (w x y z, normalised); axisangle (axis, angle); euler (three
//   turns in <compiler eulerseq>: a lower-case axis turns with the frame, q ← q ⊗ r; an upper-case
//   one is fixed, q ← r ⊗ q); xyaxes (x, then y made normal to it, z = x × y); zaxis (the
//   shortest turn taking ẑ to it). Angles in <compiler angle> units (degrees by default).
//   Geom mass: m = the `mass` given, else ρ V (ρ = density, 1000 by default); about its centre,
//     sphere r:           V = 4/3 π r³,            I = 2/5 m r² (each axis)
//     box half-sizes a b c: V = 8abc,              I_x = m (b² + c²)/3, …
//     ellipsoid a b c:     V = 4/3 π abc,          I_x = m (b² + c²)/5, …
//     cylinder r, half-length h: V = 2π r² h,      I_x = m (3r² + 4h²)/12, I_z = m r²/2
//     capsule r, h: a cylinder of mass m_c and a sphere of mass m_s = m·(4r/3)/(4r/3 + 2h),
//       I_x = m_c(3r² + 4h²)/12 + m_s(2r²/5 + h² + 3hr/4),  I_z = m_c r²/2 + 2/5 m_s r²
//   fromto (capsule, cylinder): the centre midway, ẑ from `from` to `to`, h = half the distance.
#pragma once
#include <optional>
#include <string>

#include "core/spatial/math.hpp"
#include "io/mjcf_document.hpp"

namespace femdyn::mjcf {

struct Pose {
  Vec3 p = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  Pose operator*(const Pose& b) const { return {p + R * b.p, R * b.R}; }
};

// An element's pos and orientation (the identity without them).
Pose pose_of(const Document& doc, const XMLElement& e, const std::string& cls);

// A geom's type, pose in the body frame (fromto on a capsule or cylinder sets it) and sizes as
// MuJoCo gives them: sphere r; capsule, cylinder r and half-length; box half-edges; ellipsoid
// radii (others: zero). Missing or non-positive sizes are refused, naming the geom.
struct GeomShape {
  std::string type;
  Pose pose;
  Vec3 size = Vec3::Zero();
};
GeomShape geom_shape(const Document& doc, const XMLElement& geom, const std::string& cls);

// A geom's mass, centre and inertia in the body frame, or nullopt for a geom without volume
// (a plane or height field: refused on a moving body by the caller). A mesh geom is read by
// the caller, which knows the mesh (this throws for one).
struct GeomMass {
  double mass = 0;
  Pose pose;
  Mat3 I = Mat3::Zero();  // about its centre, geom axes
};
GeomMass primitive_geom_mass(const Document& doc, const XMLElement& geom, const std::string& cls);

}  // namespace femdyn::mjcf
