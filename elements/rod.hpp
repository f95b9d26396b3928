// rod: a slender rigid rod of mass m between nodes a and b, which may lie on two different
// bodies (the coupler of a four-bar). Its mass is spread uniformly along the segment and it has
// no thickness, so its kinetic energy depends only on the end velocities:
//   T = ∫₀¹ ½ m |(1 − s) v_a + s v_b|² ds = (m/6)(|v_a|² + v_a·v_b + |v_b|²),
//   m_e = (m/6) [[2·1, 1], [1, 2·1]]   on (x y z)_a, (x y z)_b   (world axes; constant)
// exact for any motion that keeps |b − a| (checked by compile(): compile_checks.hpp). No
// torsional inertia: a rod has none about its own axis, and the bar's direction is all its
// rotation. Gravity acts as m/2 at each end. No velocity force (constant m_e in u).
#pragma once
#include <array>

#include "elements/registry.hpp"

namespace femdyn {

class Rod final : public Element {
 public:
  Rod(const Vec3& a, const Vec3& b, double mass);  // each in its own body's frame
  std::string_view type_name() const override { return "rod"; }
  std::span<const ElementNode> nodes() const override { return nodes_; }
  MatX local_mass() const override;

  static void from_params(const Params& p, ElementSink& sink);

 private:
  std::array<ElementNode, 2> nodes_;
  double mass_;
};

}  // namespace femdyn
