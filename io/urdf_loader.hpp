// Reading URDF (plain URDF; xacro is refused) into a femdyn model document — the same JSON a
// hand-written model would be — so that a robot loads, validates and exports like any model.
//   links  -> bodies with one rigid_body element (inertia rotated out of the <inertial> frame)
//   joints -> revolute / continuous / prismatic / fixed joints; <mimic> -> couplings;
//             <dynamics damping> -> joint dampers (friction is ignored, with a warning)
//   the root link is welded to the world: its children hang from "world".
// Errors: ModelError "file.urdf: joint 'elbow': axis is zero" (the element and the problem).
#pragma once
#include <string>
#include <vector>

#include "io/params.hpp"

namespace femdyn {

struct UrdfResult {
  Json model;                         // the femdyn model document
  std::vector<std::string> warnings;  // e.g. ignored friction
};

UrdfResult urdf_to_model(const std::string& xml_text, const std::string& source);
UrdfResult read_urdf(const std::string& path);

bool is_urdf_path(const std::string& path);  // by extension (.urdf)

}  // namespace femdyn
