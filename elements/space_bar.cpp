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

std::unique_ptr<SpaceBar> SpaceBar::from_section(const Vec3& a, const Vec3& b,
                                                 const BarSection& s) {
  const double l = (b - a).norm();
  const Mat3 R = bar_frame(a, b, s.section_y ? &*s.section_y : nullptr);
  const double rho_l = s.density * l;
  const Vec3 Jbar(rho_l * (s.Iy + s.Iz), rho_l * (s.Iy - s.area * l * l / 6.0),
                  rho_l * (s.Iz - s.area * l * l / 6.0));
  Mat3 J = R * Jbar.asDiagonal() * R.transpose();
  J = 0.5 * (J + J.transpose()).eval();  // exactly symmetric
  return std::make_unique<SpaceBar>(a, b, s.density * s.area * l, J);
}

std::unique_ptr<SpaceBar> SpaceBar::from_paper_lumping(const Vec3& a, const Vec3& b,
                                                       const BarSection& s) {
  // Kept to reproduce the paper's case study (docs/finger.md). Not equivalent to the bar: its
  // torsion term is ⅙ of the bar's and the axes are not the bar's.
  const double l = (b - a).norm(), rho_l = s.density * l;
  const Vec3 J(rho_l * (s.Iy + s.Iz) / 6.0, rho_l * (s.Iy - s.area * l * l / 6.0),
               rho_l * (s.Iz - s.area * l * l / 6.0));
  return std::make_unique<SpaceBar>(a, b, s.density * s.area * l, J.asDiagonal());
}

std::optional<std::string> SpaceBar::section_y_problem(const Vec3& a, const Vec3& b,
                                                       const Vec3& hint) {
  const Vec3 x = (b - a).normalized();
  if ((hint - hint.dot(x) * x).norm() < 1e-9 * (1 + hint.norm())) return "is parallel to the bar";
  return std::nullopt;
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
  if (!((b.position - a.position).norm() > 1e-12))
    p.fail("nodes", "the two nodes of a space bar coincide");
  if (p.has("mass")) {
    if (lumping != "exact")
      p.fail("lumping", "the paper's lumping is given by density and section");
    for (const char* key : {"density", "area", "Iy", "Iz", "section_y"})
      if (p.has(key)) p.fail(key, "give either mass and inertia or density, area, Iy, Iz");
    const double m = p.positive("mass");
    const Mat3 Ic = p.inertia("inertia");
    if (auto problem = inertia_problem(Ic)) p.fail("inertia", *problem);
    sink.add(from_mass_properties(a.position, b.position, m, Ic), {a.label, b.label});
    return;
  }
  if (p.has("inertia")) p.fail("inertia", "give either mass and inertia or density, area, Iy, Iz");
  BarSection section{p.positive("density"), p.positive("area"), p.positive("Iy"), p.positive("Iz"),
                     std::nullopt};
  if (p.has("section_y")) {
    section.section_y = p.vec3("section_y");
    if (auto problem = section_y_problem(a.position, b.position, *section.section_y))
      p.fail("section_y", *problem);
  }
  if (lumping == "paper") {
    if (section.section_y)
      p.fail("section_y", "the paper's lumping uses the body axes as they are");
    sink.add(from_paper_lumping(a.position, b.position, section), {a.label, b.label});
    return;
  }
  sink.add(from_section(a.position, b.position, section), {a.label, b.label});
}

}  // namespace femdyn
