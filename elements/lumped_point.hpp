// lumped_point: a mass m at a node. m_e = diag(m, m, m, 0, 0, 0); no velocity force
// (for point masses the paper's D_abc = Σ T_ia M_ij T'_jbc is exact).
#pragma once
#include "elements/registry.hpp"

namespace femdyn {

class LumpedPoint final : public Element {
 public:
  LumpedPoint(const Vec3& position, double mass);
  std::string_view type_name() const override { return "lumped_point"; }
  std::span<const ElementNode> nodes() const override { return {&node_, 1}; }
  MatX local_mass() const override;

  static void from_params(const Params& p, ElementSink& sink);

 private:
  ElementNode node_;
  double mass_;
};

}  // namespace femdyn
