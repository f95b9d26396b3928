#include "elements/lumped_point.hpp"

namespace femdyn {

LumpedPoint::LumpedPoint(const Vec3& position, double mass)
    : node_{position, {true, true, true, false, false, false}}, mass_(mass) {}

MatX LumpedPoint::local_mass() const {
  MatX m = MatX::Zero(6, 6);
  m.topLeftCorner<3, 3>() = mass_ * Mat3::Identity();
  return m;
}

// {"type": "lumped_point", "node": N, "mass": m}
void LumpedPoint::from_params(const Params& p, ElementSink& sink) {
  p.allow_only({"type", "node", "mass"});
  const NodeRef n = p.node("node");
  sink.add(std::make_unique<LumpedPoint>(n.position, p.positive("mass")), {n.label});
}

}  // namespace femdyn
