// Robot files (URDF, MJCF) as femdyn JSON documents, for io/model_file.cpp and io/model_loader.cpp:
// given directly, or by reference from a JSON file ({"model": "urdf" | "mjcf", "params": {"file",
// …}}, the file's own name, description, gravity and loads on top). Not an interface of femdyn.
#pragma once
#include <optional>
#include <string>
#include <utility>

#include "io/model_loader.hpp"
#include "io/params.hpp"

namespace femdyn {

// The reference forms' model names.
inline constexpr const char* kUrdfReference = "urdf";
inline constexpr const char* kMjcfReference = "mjcf";

// {"model", "params", …}: the keys of a plugin's (or a robot reference's) form, checked.
Params plugin_form(const Json& root, const std::string& source);
// The file's own name, description, gravity and loads (and frames, constraints, springs) on top
// of the document it expands to.
void apply_overrides(const Json& root, const Params& p, Json& doc);

// A URDF or MJCF file as femdyn JSON, its warnings to options.warn. --floating-base is for URDF.
Json robot_document(const std::string& path, const LoadOptions& options);

// A JSON file {"model": "urdf" | "mjcf", …}: the robot file it names as femdyn JSON, and that
// file's path for messages; nullopt for any other document.
std::optional<std::pair<Json, std::string>> robot_reference(const std::string& path,
                                                            const Json& root,
                                                            const LoadOptions& options);

// An error found after conversion, renamed by the robot file's link (MJCF: body) and joint
// rather than the generated JSON path: "robot.urdf: /bodies/3/joint: …" becomes "robot.urdf:
// joint 'elbow' (link 'forearm'): …".
[[noreturn]] void rethrow_for_robot_file(const ModelError& e, const Json& doc,
                                         const std::string& path);

// --balance-inertia on a JSON model: refused (its inertias are its author's, to be corrected).
void refuse_balance_on_json(const std::string& path, const LoadOptions& options);

}  // namespace femdyn
