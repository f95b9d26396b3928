// The scene a page draws, as one JSON document: the model's bodies (parent, joint type, axes and
// origin), named frames, elements as the method sees them (type, mass, inertia, each node on
// its body), the robot file's visuals (primitives; STL/OBJ meshes embedded as base64 arrays,
// Collada as its text; what is not drawn is listed with why), each body without visuals as its
// inertia box, the loop constraints' two places, and the motion: each body's pose per frame (core
// kinematics, so the page never re-implements them), q and the energy balance. The page's script
// (web/view.js) reads it; "counts" says what the page must hold (its tests compare them).
#pragma once
#include <string>
#include <vector>

#include "core/model/model.hpp"
#include "io/params.hpp"
#include "io/visual.hpp"
#include "view/motion.hpp"

namespace femdyn::view {

// At most this many mesh triangles on a page (about 50 MB of page): a page a browser opens.
inline constexpr std::size_t kMaxPageTriangles = 2'000'000;
// And at most this much Collada text (URDF .dae meshes, read by three.js in the page).
inline constexpr std::size_t kMaxPageColladaBytes = 64u << 20;

// `source` names the model in the page (a file name, no directory). A visual's link is a body
// or a named frame (a link welded into a body); one that is neither (a URDF's root link welded
// to the world) is drawn on the world.
Json scene_json(const Model& model, const Motion& motion, const std::vector<Visual>& visuals,
                const std::string& source);

}  // namespace femdyn::view
