// The scene a page draws, as one JSON document: the model's bodies (parent, joint type, axes and
// origin), named frames, elements as the method sees them (type, mass, inertia, each node on
// its body), URDF visuals, and the motion: each body's pose per frame (core kinematics, so the
// page never re-implements them), q and the energy balance. The page's script (web/view.js)
// reads it; "counts" says what the page must hold (its tests compare them).
#pragma once
#include <string>
#include <vector>

#include "core/model.hpp"
#include "io/params.hpp"
#include "io/urdf_loader.hpp"
#include "view/motion.hpp"

namespace femdyn::view {

// `source` names the model in the page (a file name, no directory). Visuals on a link that is
// not a body (the root link welded to the world) are drawn on the world.
Json scene_json(const Model& model, const Motion& motion, const std::vector<UrdfVisual>& visuals,
                const std::string& source);

}  // namespace femdyn::view
