#include "elements/space_bar.hpp"

#include "core/spatial/inertia.hpp"

namespace femdyn {

namespace {
constexpr std::array<bool, 6> kAll = {true, true, true, true, true, true};
}

SpaceBar::SpaceBar(const Vec3& a, const Vec3& b, double mass, const Mat3& J_rot_body)
    : nodes_{ElementNode{a, kAll}, ElementNode{b, kAll}}, mass_(mass), J_(J_rot_body) {}

MatX SpaceBar::local_mass() const {
  // ½ [m, m, m, J, m, m, m, J]: half the mass and half of J_rot at each end.
  MatX m = MatX::Zero(12, 12);
  for (int end = 0; end < 2; ++end) {
    m.block<3, 3>(6 * end, 6 * end) = 0.5 * mass_ * Mat3::Identity();
    m.block<3, 3>(6 * end + 3, 6 * end + 3) = 0.5 * J_;
  }
  return m;
}

void SpaceBar::add_velocity_force(const Eigen::Ref<const VecX>& x, const Eigen::Ref<const VecX>& y,
                                  Eigen::Ref<VecX> g) const {
  // Each end carries J/2 turning with the bar's ω: g_end = x_ω × (J/2 y_ω).
  const Mat3 half = 0.5 * J_;
  for (int end = 0; end < 2; ++end)
    add_gyroscopic(half, x.segment<3>(6 * end + 3), y.segment<3>(6 * end + 3),
                   g.segment<3>(6 * end + 3));
}

Mat3 SpaceBar::bar_frame(const Vec3& a, const Vec3& b, const Vec3* y_hint) {
  const Vec3 x = (b - a).normalized();
  Vec3 y;
  if (y_hint) {
    y = *y_hint - y_hint->dot(x) * x;
  } else {
    int k = 0;
    x.cwiseAbs().minCoeff(&k);
    y = Vec3::Unit(k) - x[k] * x;
  }
  y.normalize();
  Mat3 R;
  R << x, y, x.cross(y);
  return R;
}

std::unique_ptr<SpaceBar> SpaceBar::from_mass_properties(const Vec3& a, const Vec3& b, double m,
                                                         const Mat3& I_c) {
  const Vec3 half = 0.5 * (b - a);
  Mat3 J = I_c - point_inertia(m, half);  // ends m/2 at ±(l/2) x
  J = 0.5 * (J + J.transpose()).eval();
  return std::make_unique<SpaceBar>(a, b, m, J);
}

// {"type": "space_bar", "nodes": [a, b], "density": ρ, "area": A, "Iy": …, "Iz": …,
//  "section_y": [..]}  or  {"type": "space_bar", "nodes": [a, b], "mass": m, "inertia": I_c}
void SpaceBar::from_params(const Params& p, ElementSink& sink) {
  p.allow_only(
      {"type", "nodes", "density", "area", "Iy", "Iz", "section_y", "mass", "inertia", "lumping"});
  const std::string lumping = p.has("lumping") ? p.string("lumping") : "exact";
  if (lumping != "exact" && lumping != "paper")
    p.fail("lumping", "expected \"exact\" or \"paper\", got \"" + lumping + "\"");
  if (!p.has("nodes") || !p.json().at("nodes").is_array() || p.json().at("nodes").size() != 2)
    p.fail("nodes", "expected the bar's 2 nodes [a, b]");
  const NodeRef a = p.node_at("nodes", 0), b = p.node_at("nodes", 1);
  const double l = (b.position - a.position).norm();
  if (!(l > 1e-12)) p.fail("nodes", "the two nodes of a space bar coincide");
  const Vec3 x = (b.position - a.position) / l;
  double m;
  Mat3 J;
  if (p.has("mass")) {
    if (lumping != "exact")
      p.fail("lumping", "the paper's lumping is given by density and section");
    for (const char* key : {"density", "area", "Iy", "Iz", "section_y"})
      if (p.has(key)) p.fail(key, "give either mass and inertia or density, area, Iy, Iz");
    m = p.positive("mass");
    const Mat3 Ic = p.inertia("inertia");
    if (auto problem = inertia_problem(Ic)) p.fail("inertia", *problem);
    sink.add(from_mass_properties(a.position, b.position, m, Ic), {a.label, b.label});
    return;
  } else {
    if (p.has("inertia"))
      p.fail("inertia", "give either mass and inertia or density, area, Iy, Iz");
    const double rho = p.positive("density"), A = p.positive("area");
    const double Iy = p.positive("Iy"), Iz = p.positive("Iz");
    Vec3 hint;
    const bool has_hint = p.has("section_y");
    if (has_hint) {
      hint = p.vec3("section_y");
      if ((hint - hint.dot(x) * x).norm() < 1e-9 * (1 + hint.norm()))
        p.fail("section_y", "is parallel to the bar");
    }
    const Mat3 R = bar_frame(a.position, b.position, has_hint ? &hint : nullptr);
    m = rho * A * l;
    if (lumping == "paper") {
      // The paper's printed lumping, kept to reproduce its case study (docs/finger.md):
      // J = diag(⅙ρl(I_y+I_z), ρl(I_y − A l²/6), ρl(I_z − A l²/6)) on the body axes as they are.
      // Not equivalent to the bar: its torsion term is ⅙ of the bar's and the axes are not
      // the bar's.
      if (has_hint) p.fail("section_y", "the paper's lumping uses the body axes as they are");
      J = Vec3(rho * l * (Iy + Iz) / 6.0, rho * l * (Iy - A * l * l / 6.0),
               rho * l * (Iz - A * l * l / 6.0))
              .asDiagonal();
      sink.add(std::make_unique<SpaceBar>(a.position, b.position, m, J), {a.label, b.label});
      return;
    }
    const Vec3 Jbar(rho * l * (Iy + Iz), rho * l * (Iy - A * l * l / 6.0),
                    rho * l * (Iz - A * l * l / 6.0));
    J = R * Jbar.asDiagonal() * R.transpose();
    J = 0.5 * (J + J.transpose()).eval();  // exactly symmetric
  }
  sink.add(std::make_unique<SpaceBar>(a.position, b.position, m, J), {a.label, b.label});
}

}  // namespace femdyn
