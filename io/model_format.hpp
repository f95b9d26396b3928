// Which format a model file is in, from its name and, failing that, its content: .urdf and
// .xacro are URDF (a .xacro is read to say it needs expanding), .json is femdyn JSON, .mjcf is
// MJCF; any other file is sniffed: its first element (past <?xml …?>, comments and blanks)
// <robot> is URDF, <mujoco> is MJCF; anything else is read as JSON.
#pragma once
#include <string>

namespace femdyn {

enum class ModelFormat { json, urdf, mjcf };

ModelFormat model_format(const std::string& path);
inline bool is_urdf_path(const std::string& path) {
  return model_format(path) == ModelFormat::urdf;
}
inline bool is_mjcf_path(const std::string& path) {
  return model_format(path) == ModelFormat::mjcf;
}
// URDF or MJCF: a robot file read into femdyn JSON.
inline bool is_robot_file(const std::string& path) {
  return model_format(path) != ModelFormat::json;
}

}  // namespace femdyn
