// rotary_node: a rotary inertia J (body frame) at a node, turning with its body at ω.
//   m_e = diag(0, 0, 0, J),   g_e(x, y) = x_ω × (J y_ω)   (the gyroscopic term ω × (J ω))
// The gyroscopic term is absent from the paper's D_abc; without it every 3D case is wrong.
#pragma once
#include "elements/registry.hpp"

namespace femdyn {

class RotaryNode final : public Element {
 public:
  RotaryNode(const Vec3& position, const Mat3& J);
  std::string_view type_name() const override { return "rotary_node"; }
  std::span<const ElementNode> nodes() const override { return {&node_, 1}; }
  MatX local_mass() const override;
  bool has_velocity_force() const override { return true; }
  void add_velocity_force(const Eigen::Ref<const VecX>& x, const Eigen::Ref<const VecX>& y,
                          Eigen::Ref<VecX> g) const override;

  static void from_params(const Params& p, ElementSink& sink);

 private:
  ElementNode node_;
  Mat3 J_;
};

}  // namespace femdyn
