#include "elements/rod.hpp"

namespace femdyn {

Rod::Rod(const Vec3& a, const Vec3& b, double mass)
    : nodes_{ElementNode{a, {true, true, true, false, false, false}},
             ElementNode{b, {true, true, true, false, false, false}}},
      mass_(mass) {}

MatX Rod::local_mass() const {
  MatX m = MatX::Zero(12, 12);
  const Mat3 I = Mat3::Identity();
  m.block<3, 3>(0, 0) = m.block<3, 3>(6, 6) = (mass_ / 3) * I;
  m.block<3, 3>(0, 6) = m.block<3, 3>(6, 0) = (mass_ / 6) * I;
  return m;
}

// {"type": "rod", "nodes": [a, b], "mass": m}; a node of another body as "body/node"
void Rod::from_params(const Params& p, ElementSink& sink) {
  p.allow_only({"type", "nodes", "mass"});
  const NodeRef a = p.node_at("nodes", 0), b = p.node_at("nodes", 1);
  if (p.json().at("nodes").size() != 2) p.fail("nodes", "a rod has exactly 2 nodes");
  if (a.label == b.label) p.fail("nodes", "the two nodes of a rod are the same node");
  sink.add(std::make_unique<Rod>(a.position, b.position, p.positive("mass")), {a.label, b.label});
}

}  // namespace femdyn
