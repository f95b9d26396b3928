#include "core/model/loop_constraint.hpp"

namespace femdyn {

namespace {
constexpr std::pair<ConstraintType, const char*> kNames[] = {
    {ConstraintType::Ball, "ball"},
    {ConstraintType::Weld, "weld"},
    {ConstraintType::Distance, "distance"},
    {ConstraintType::PointOnLine, "point_on_line"},
    {ConstraintType::PointOnPlane, "point_on_plane"},
    {ConstraintType::Gear, "gear"}};
}  // namespace

int LoopConstraint::rows() const {
  switch (type) {
    case ConstraintType::Ball:
      return axes.empty() ? 3 : static_cast<int>(axes.size());
    case ConstraintType::Weld:
      return 6;
    case ConstraintType::PointOnLine:
    case ConstraintType::PointOnPlane:
      return static_cast<int>(axes.size());
    case ConstraintType::Distance:
    case ConstraintType::Gear:
      break;
  }
  return 1;
}

const char* constraint_type_name(ConstraintType type) {
  for (const auto& [t, name] : kNames)
    if (t == type) return name;
  return "ball";
}

bool parse_constraint_type(const std::string& text, ConstraintType& type) {
  for (const auto& [t, name] : kNames)
    if (text == name) {
      type = t;
      return true;
    }
  return false;
}

}  // namespace femdyn
