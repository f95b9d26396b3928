// What a robot file says a body looks like: its visual geometry, read for `femdyn view`
// (view/scene.hpp) by the URDF and MJCF readers; the equations never see it.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn {

// One shape, in the frame of `link`: a body of the model or a frame welded to one (a URDF link
// on a fixed joint). Sizes: box — the full edges x y z; cylinder and capsule — radius and the
// length of the cylinder along z; sphere — radius; ellipsoid — the three radii; mesh — its scale.
struct Visual {
  std::string link;
  std::string shape;  // box, cylinder, capsule, sphere, ellipsoid, mesh; "invalid": not read
  Vec3 size = Vec3::Zero();
  std::string mesh;        // a mesh's file as the robot file names it
  std::string mesh_path;   // where it was found, or empty (then the page says why)
  std::string mesh_issue;  // why the mesh was not found, or the visual not read
  Vec3 xyz = Vec3::Zero();
  Mat3 R = Mat3::Identity();
  std::optional<Eigen::Vector4d> rgba;
};

// A visual the reader could not read, on `link`: the page lists it with `why`; no load stops.
inline Visual unread_visual(const std::string& link, const std::string& why) {
  Visual v;
  v.link = link;
  v.shape = "invalid";
  v.mesh_issue = why;
  return v;
}

}  // namespace femdyn
