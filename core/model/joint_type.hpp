// The joint types and their names in model files: the one list a new joint type joins
// (docs/design.md, "Adding a joint type").
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace femdyn {

enum class JointType { Revolute, Prismatic, Fixed, Helical, Universal, Planar, Spherical, Free };

// The names a model file may give each type ("continuous" is URDF's unlimited revolute).
struct JointTypeName {
  std::string_view name;
  JointType type;
};
inline constexpr std::array<JointTypeName, 11> kJointTypeNames{{
    {"revolute", JointType::Revolute},
    {"continuous", JointType::Revolute},
    {"prismatic", JointType::Prismatic},
    {"fixed", JointType::Fixed},
    {"helical", JointType::Helical},
    {"screw", JointType::Helical},
    {"universal", JointType::Universal},
    {"planar", JointType::Planar},
    {"spherical", JointType::Spherical},
    {"ball", JointType::Spherical},
    {"free", JointType::Free},
}};

inline std::optional<JointType> joint_type_named(std::string_view name) {
  for (const JointTypeName& t : kJointTypeNames)
    if (t.name == name) return t.type;
  return std::nullopt;
}

// The canonical name (the first listed for the type).
inline std::string_view joint_type_name(JointType type) {
  for (const JointTypeName& t : kJointTypeNames)
    if (t.type == type) return t.name;
  return "?";
}

// "revolute, continuous, prismatic, …, spherical, ball or free": the names, for a message.
inline std::string joint_type_list() {
  std::string out;
  for (std::size_t k = 0; k < kJointTypeNames.size(); ++k) {
    if (k > 0) out += k + 1 == kJointTypeNames.size() ? " or " : ", ";
    out += kJointTypeNames[k].name;
  }
  return out;
}

}  // namespace femdyn
