#include "core/joints/parameters.hpp"

#include <string>

#include "core/joints/kernel.hpp"

namespace femdyn {

const JointScalar* joint_scalar(JointType type, std::string_view key) {
  for (const JointScalar& s : joint_parameters(type).scalars)
    if (s.key == key) return &s;
  return nullptr;
}

bool is_joint_scalar(std::string_view key) {
  for (const JointTypeName& t : kJointTypeNames)
    if (joint_scalar(t.type, key)) return true;
  return false;
}

std::string joint_axis_refusal(JointType type) {
  return "a " + std::string(joint_type_name(type)) +
         " joint turns about every axis: it takes no axis";
}

std::string joint_axis2_refusal() {
  std::string types;  // the canonical names of the types of two axes
  for (const JointTypeName& t : kJointTypeNames)
    if (t.name == joint_type_name(t.type) && joint_parameters(t.type).axes == JointAxes::Two)
      types += (types.empty() ? "" : " or ") + std::string(t.name);
  return "only a " + types + " joint has a second axis";
}

std::string joint_scalar_refusal(std::string_view key) {
  std::string types;  // the canonical names of the types that take it
  for (const JointTypeName& t : kJointTypeNames)
    if (t.name == joint_type_name(t.type) && joint_scalar(t.type, key))
      types += (types.empty() ? "" : " or ") + std::string(t.name);
  if (types.empty()) return "no joint type has a " + std::string(key);
  return "only a " + types + " joint has a " + std::string(key);
}

}  // namespace femdyn
