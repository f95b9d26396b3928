#include "elements/registry.hpp"

#include <array>

#include "elements/lumped_point.hpp"
#include "elements/rigid_body.hpp"
#include "elements/rotary_node.hpp"
#include "elements/space_bar.hpp"

namespace femdyn {

// The one place element types are registered.
static const std::array kTypes = {
    ElementType{"lumped_point", &LumpedPoint::from_params, "a mass at a node"},
    ElementType{"space_bar", &SpaceBar::from_params,
                "a rigid bar lumped to its two end nodes, with its rotary inertia"},
    ElementType{"rotary_node", &RotaryNode::from_params,
                "a rotary inertia at a node, with its gyroscopic term"},
    ElementType{"rigid_body", &RigidBodyShorthand::from_params,
                "mass, centre of mass, inertia: turned into equivalent elements"},
};

std::span<const ElementType> element_types() { return kTypes; }

const ElementType* find_element_type(std::string_view name) {
  for (const ElementType& t : kTypes)
    if (t.name == name) return &t;
  return nullptr;
}

}  // namespace femdyn
