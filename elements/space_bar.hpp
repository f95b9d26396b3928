// space_bar: a rigid bar between nodes a and b (bar frame: x along b − a, length l), lumped as
//   m/2 at each end (m = ρ A l) and the rotary inertia J_rot split half to each end, with
//   J_rot = ρ l diag(I_y + I_z, I_y − A l²/6, I_z − A l²/6)          (bar frame)
// so that end masses + J_rot have the bar's mass, centroid and inertia
//   ρ l diag(I_y + I_z, I_y + A l²/12, I_z + A l²/12)   about the centroid.
// Given by mass and centroidal inertia instead: J_rot = I_c − (m l²/4)(1 − x̂ x̂ᵀ).
// J_rot is usually indefinite (J_y, J_z < 0): the element total is what is physical, and both
// ends turn with the bar's own ω, so the gyroscopic term is ω × (J_rot ω).
// "lumping": "paper" reproduces the paper's printed (erroneous) lumping for its case study.
#pragma once
#include <array>
#include <optional>

#include "elements/registry.hpp"

namespace femdyn {

// A uniform bar's material and section: density ρ, area A and the second moments I_y, I_z
// about the section's axes ŷ, ẑ; ŷ is section_y projected off the bar (see bar_frame).
struct BarSection {
  double density = 0, area = 0, Iy = 0, Iz = 0;
  std::optional<Vec3> section_y;
};

class SpaceBar final : public Element {
 public:
  // J_rot in the body frame.
  SpaceBar(const Vec3& a, const Vec3& b, double mass, const Mat3& J_rot_body);
  std::string_view type_name() const override { return "space_bar"; }
  std::span<const ElementNode> nodes() const override { return nodes_; }
  MatX local_mass() const override;
  bool has_velocity_force() const override { return true; }
  void add_velocity_force(const Eigen::Ref<const VecX>& x, const Eigen::Ref<const VecX>& y,
                          Eigen::Ref<VecX> g) const override;

  // Bar frame (columns x̂ ŷ ẑ in body axes): x̂ along b − a; ŷ from the hint projected off x̂
  // (default: the body axis least aligned with x̂).
  static Mat3 bar_frame(const Vec3& a, const Vec3& b, const Vec3* y_hint);
  // The bar of mass m and centroidal inertia I_c (body axes) between a and b: m/2 at each end
  // and J_rot = I_c − (m l²/4)(1 − x̂ x̂ᵀ), the rest of I_c (the JSON form with "mass" and
  // "inertia"; a ≠ b and I_c physical are checked by the caller).
  static std::unique_ptr<SpaceBar> from_mass_properties(const Vec3& a, const Vec3& b, double m,
                                                        const Mat3& I_c);
  // The bar of this section between a and b, J_rot as above (the JSON form with "density";
  // a ≠ b, positive numbers and section_y_problem checked by the caller).
  static std::unique_ptr<SpaceBar> from_section(const Vec3& a, const Vec3& b,
                                                const BarSection& section);
  // The paper's printed lumping (its case study only): J_rot = diag(⅙ρl(I_y+I_z),
  // ρl(I_y − A l²/6), ρl(I_z − A l²/6)) on the body axes as they are.
  static std::unique_ptr<SpaceBar> from_paper_lumping(const Vec3& a, const Vec3& b,
                                                      const BarSection& section);
  // Why section_y cannot orient the bar a → b (it is parallel to it), or nothing.
  static std::optional<std::string> section_y_problem(const Vec3& a, const Vec3& b,
                                                      const Vec3& section_y);
  static void from_params(const Params& p, ElementSink& sink);

 private:
  std::array<ElementNode, 2> nodes_;
  double mass_;
  Mat3 J_;  // J_rot, body frame
};

}  // namespace femdyn
