// Reading MJCF (MuJoCo's format) into a femdyn model document — the same JSON a hand-written
// model would be — so that a MuJoCo model loads, validates and exports like any model.
//   <worldbody>'s body tree -> bodies. A body's joints (hinge, slide, ball, free; several in one
//     body, as MJCF allows) become a chain: each joint's frame sits at its pos in the body's axes,
//     and a body with k joints is k femdyn bodies, the first k − 1 massless and named
//     "body.joint"; the last carries the body's name and mass, its frame the last joint's. A body
//     without joints is welded (a fixed joint). Unnamed bodies and joints are named "body<i>",
//     "joint<i>" after MuJoCo's index. A hinge or slide's coordinate is MuJoCo's qpos (its `ref`
//     is in the joint's origin); a free joint's q is MuJoCo's qpos (the body's pose in the world).
//   Mass: <inertial> (diaginertia or fullinertia, in its own frame), or the body's primitive
//     geoms (<compiler inertiafromgeom>, mass or density, inertiagrouprange), boundmass,
//     boundinertia, settotalmass, balanceinertia as MuJoCo's compiler. A mesh geom (STL or OBJ
//     file, or inline vertex/face) weighs the solid it bounds, by MuJoCo's legacy algorithm or
//     the exact one (exactmeshinertia, or the mesh's inertia="exact"): io/mjcf_mesh.cpp.
//   Joint armature, damping, frictionloss (as Coulomb friction), stiffness/springref, range with
//     limited/autolimits. <option gravity>. <equality> connect -> a ball constraint, weld -> a
//     weld, joint -> a coupling (its polynomial), tendon (fixed, linear) -> a linear coupling.
//   A body's named sites -> frames on its femdyn body.
//   What femdyn does not model (contacts, actuators, sensors, tendons, keyframes, …) is
//   reported once, in one line.
// Errors: ModelError "arm.xml: <joint name='elbow'> (line 12): axis is zero".
#pragma once
#include <string>
#include <vector>

#include "io/params.hpp"
#include "io/visual.hpp"

namespace femdyn {

struct MjcfOptions {
  bool balance_inertia = false;  // a body's non-physical inertia -> the nearest physical one
  // Every mesh's exact solid, as <compiler exactmeshinertia="true"> (MuJoCo's default is its
  // legacy inertia, which overcounts a non-convex mesh): how validate meets MuJoCo 2.2.
  bool exact_mesh_inertia = false;
};

// Where the bodies' mass came from, for validate's comparison with MuJoCo (whose compiler holds
// meshes in single precision and diagonalises a full tensor by an iteration that stops early):
// mesh geoms that gave mass, those whose MuJoCo legacy solid (each tetrahedron's volume taken
// positive) is not the solid the mesh bounds (a non-convex mesh), each "'name' (file 'x.stl')
// (×r)", r the legacy volume over the solid's, and the <inertial fullinertia> read.
struct MjcfMassNotes {
  int mesh_geoms = 0;
  std::vector<std::string> not_solid;
  int full_inertias = 0;
};

struct MjcfResult {
  Json model;                         // the femdyn model document
  std::vector<std::string> warnings;  // what is not modelled, what was repaired
  MjcfMassNotes mass_notes;
  std::vector<Visual> visuals;  // what the bodies look like (io/mjcf_visuals.cpp)
};

MjcfResult read_mjcf(const std::string& path, const MjcfOptions& options = {});

}  // namespace femdyn
