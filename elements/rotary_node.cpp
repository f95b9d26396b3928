#include "elements/rotary_node.hpp"

#include "core/spatial/inertia.hpp"

namespace femdyn {

RotaryNode::RotaryNode(const Vec3& position, const Mat3& J)
    : node_{position, {false, false, false, true, true, true}}, J_(J) {}

MatX RotaryNode::local_mass() const {
  MatX m = MatX::Zero(6, 6);
  m.bottomRightCorner<3, 3>() = J_;
  return m;
}

void RotaryNode::add_velocity_force(const Eigen::Ref<const VecX>& x,
                                    const Eigen::Ref<const VecX>& y, Eigen::Ref<VecX> g) const {
  add_gyroscopic(J_, x.segment<3>(3), y.segment<3>(3), g.segment<3>(3));
}

// {"type": "rotary_node", "node": N, "inertia": J}   J physical (triangle inequality)
void RotaryNode::from_params(const Params& p, ElementSink& sink) {
  p.allow_only({"type", "node", "inertia"});
  const NodeRef n = p.node("node");
  const Mat3 J = p.inertia("inertia");
  if (auto problem = inertia_problem(J)) p.fail("inertia", *problem);
  sink.add(std::make_unique<RotaryNode>(n.position, J), {n.label});
}

}  // namespace femdyn
