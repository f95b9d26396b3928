#include "elements/registry.hpp"

#include <array>

#include "elements/lumped_point.hpp"
#include "elements/rigid_body.hpp"
#include "elements/rod.hpp"
#include "elements/rotary_node.hpp"
#include "elements/space_bar.hpp"

namespace femdyn {

// The one place element types are registered.
static const std::array kTypes = {
    ElementType{"lumped_point", &LumpedPoint::from_params},  // a mass at a node
    ElementType{"space_bar", &SpaceBar::from_params},  // a rigid bar lumped to its two end nodes
    ElementType{"rotary_node", &RotaryNode::from_params},         // a rotary inertia at a node
    ElementType{"rigid_body", &RigidBodyShorthand::from_params},  // mass, com, inertia
    ElementType{"rod", &Rod::from_params},  // a slender rod, its ends possibly on two bodies
};

const Registry<ElementType>& element_types() {
  static const Registry<ElementType> registry{kTypes};
  return registry;
}

}  // namespace femdyn
