// Reading URDF (plain URDF; xacro is refused) into a femdyn model document — the same JSON a
// hand-written model would be — so that a robot loads, validates and exports like any model.
//   links  -> bodies with one rigid_body element (inertia rotated out of the <inertial> frame);
//             the links welded by fixed joints are checked as one rigid body (a non-physical
//             sensor or dummy link is merged into it); `balance_inertia` replaces a body's
//             non-physical inertia by the nearest physical one, each change reported
//   joints -> revolute / continuous / prismatic / fixed / planar joints, floating -> free;
//             <mimic> -> couplings;
//             <dynamics damping friction> -> joint dampers and Coulomb friction
//             <limit effort velocity> -> effort limits (τ saturated) and velocity limits (reported)
//   the root link is welded to the world (its children hang from "world"), or with
//   `floating_base` a body of its own on a free joint named after it (a floating base).
// Errors: ModelError "file.urdf: joint 'elbow': axis is zero" (the element and the problem).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/spatial/math.hpp"
#include "io/model_format.hpp"
#include "io/params.hpp"
#include "io/visual.hpp"

namespace femdyn {

struct UrdfResult {
  Json model;                         // the femdyn model document
  std::vector<std::string> warnings;  // e.g. ignored friction
};

struct UrdfOptions {
  bool floating_base = false;    // a free joint between the world and the root link
  bool balance_inertia = false;  // a body's non-physical inertia -> the nearest physical one
};
UrdfResult urdf_to_model(const std::string& xml_text, const std::string& source,
                         const UrdfOptions& options = {});
UrdfResult read_urdf(const std::string& path, const UrdfOptions& options = {});

// The links' <visual>s (io/visual.hpp), each in its link's frame: box, cylinder, sphere, or a
// mesh whose filename is found relative to the URDF's folder, as file://, or as
// package://NAME/… in a folder NAME above the URDF or on ROS_PACKAGE_PATH. A visual that cannot
// be read comes back with shape "invalid" and why in mesh_issue (it stops no load).
std::vector<Visual> urdf_visuals(const std::string& xml_text, const std::string& source);

}  // namespace femdyn
