#include "io/flexible_bar.hpp"

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "core/model/limits.hpp"
#include "core/model/names.hpp"

namespace femdyn {

namespace {

// The section's stiffnesses and mass per unit length.
struct Section {
  double EA = 0, EIy = 0, EIz = 0, GJ = 0;  // N, N m², N m², N m²
  double rhoA = 0, rhoIy = 0, rhoIz = 0;    // kg/m, kg m (rotary inertia per length)
};

// {"E", "G", "density", "area", "Iy", "Iz", "J"} or {"EA", "EIy", "EIz", "GJ", "rhoA", "rhoIy",
// "rhoIz"}; what a locked deformation does not use may be left out.
Section read_section(const Params& s, bool axial, bool torsion) {
  Section out;
  if (s.has("E")) {
    s.allow_only({"E", "G", "density", "area", "Iy", "Iz", "J"});
    const double E = s.positive("E"), rho = s.positive("density"), A = s.positive("area");
    const double Iy = s.positive("Iy"), Iz = s.positive("Iz");
    out = {E * A, E * Iy, E * Iz, 0, rho * A, rho * Iy, rho * Iz};
    if (torsion) out.GJ = s.positive("G") * s.positive("J");
    return out;
  }
  s.allow_only({"EA", "EIy", "EIz", "GJ", "rhoA", "rhoIy", "rhoIz"});
  if (!s.has("EIy") && !s.has("EIz"))
    s.fail("EIy",
           "give the section as E, G, density, area, Iy, Iz, J or as EA, EIy, EIz, GJ, "
           "rhoA (rhoIy, rhoIz)");
  out.EIy = s.positive("EIy");
  out.EIz = s.positive("EIz");
  out.rhoA = s.positive("rhoA");
  if (axial || s.has("EA")) out.EA = s.positive("EA");
  if (torsion) out.GJ = s.positive("GJ");
  // The rotary inertia: given, or a homogeneous section's, ρI = ρA I/A = ρA EI/EA. Without it a
  // long chain of pieces has articulated inertias that vanish geometrically along the bar.
  for (auto [key, rhoI, EI] :
       {std::tuple{"rhoIy", &out.rhoIy, out.EIy}, std::tuple{"rhoIz", &out.rhoIz, out.EIz}}) {
    if (s.has(key))
      *rhoI = s.positive(key);
    else if (out.EA > 0)
      *rhoI = out.rhoA * EI / out.EA;
    else
      s.fail(key,
             "is needed when EA is not given (the section's rotary inertia per length, "
             "kg m; a homogeneous section has ρA EI/EA)");
  }
  return out;
}

Json vec(const Vec3& v) { return Json::array({v[0], v[1], v[2]}); }

// The bar's rest shape: straight (κ = 0), or an arc of curvature κ = 1/R turning about `axis`
// (a unit vector across the bar, in its frame). A stretch of arc length s turns its tangent by
// κ s and spans the chord 2 sin(κ s/2)/κ, at half that turn from the tangent where it starts.
struct RestShape {
  double kappa = 0;
  Vec3 axis = Vec3::UnitZ();
  Mat3 turn(double s) const { return axis_rotation(axis, kappa * s); }
  double chord(double s) const { return kappa == 0 ? s : 2 * std::sin(kappa * s / 2) / kappa; }
  // The chord of a stretch s, in the frame of the tangent where it starts.
  Vec3 chord_vector(double s) const { return turn(s / 2) * Vec3(chord(s), 0, 0); }
};

// A rigid piece of the bar: the stretch of arc length s from its body's origin, as the straight
// piece along its chord (its mass ρA s, its rotary inertia about the chord's direction).
Json piece(const Section& sec, const RestShape& shape, double s) {
  const double m = sec.rhoA * s, l = shape.chord(s);
  const double Ixx = (sec.rhoIy + sec.rhoIz) * s, Iyy = sec.rhoIy * s + m * l * l / 12,
               Izz = sec.rhoIz * s + m * l * l / 12;
  const Mat3 R = shape.turn(s / 2);  // the chord's axes in the body's
  const Mat3 I = R * Vec3(Ixx, Iyy, Izz).asDiagonal() * R.transpose();
  return Json::array({{{"type", "rigid_body"},
                       {"mass", m},
                       {"com", vec(shape.chord_vector(s) / 2)},
                       {"inertia",
                        {{I(0, 0), I(0, 1), I(0, 2)},
                         {I(1, 0), I(1, 1), I(1, 2)},
                         {I(2, 0), I(2, 1), I(2, 2)}}}}});
}

// A joint's origin: the chord before it, and (on a curved bar) the turn of the tangent.
Json origin(const RestShape& shape, double s) {
  Json o = {{"xyz", vec(shape.chord_vector(s))}};
  if (shape.kappa != 0) {
    const Eigen::Quaterniond q(shape.turn(s));
    o["quat"] = Json::array({q.w(), q.x(), q.y(), q.z()});
  }
  return o;
}

// "damping": {"stiffness_proportional": β, "mass_proportional": α, "modal": ζ or [ζ1, ζ2, …]}.
struct Damping {
  double stiffness_proportional = 0, mass_proportional = 0;
  std::vector<double> modal;
};
Damping read_damping(const Params& p) {
  Damping out;
  if (!p.has("damping")) return out;
  const Params d = p.child("damping");
  d.allow_only({"stiffness_proportional", "mass_proportional", "modal"});
  out.stiffness_proportional =
      d.has("stiffness_proportional") ? d.non_negative("stiffness_proportional") : 0.0;
  out.mass_proportional = d.has("mass_proportional") ? d.non_negative("mass_proportional") : 0.0;
  if (!d.has("modal")) return out;
  const Json& z = d.json().at("modal");
  if (z.is_number()) {
    out.modal = {d.non_negative("modal")};
    return out;
  }
  if (!z.is_array() || z.empty())
    d.fail("modal", "expected a damping ratio, or a non-empty array of them (mode by mode)");
  for (std::size_t k = 0; k < z.size(); ++k) {
    const double ratio = json_number(z[k], d.path("modal") + "/" + std::to_string(k));
    if (!(ratio >= 0)) d.fail("modal", "ratio " + std::to_string(k) + " must be at least 0");
    out.modal.push_back(ratio);
  }
  return out;
}

// "curvature": {"radius": R, "axis": [ax, ay, az]} (the axis across the bar, default z).
RestShape read_rest_shape(const Params& p) {
  RestShape shape;
  if (!p.has("curvature")) return shape;
  const Params c = p.child("curvature");
  c.allow_only({"radius", "axis"});
  shape.kappa = 1 / c.positive("radius");
  const Vec3 axis = c.vec3_or("axis", Vec3::UnitZ());
  if (!(axis.norm() > 0) || std::abs(axis.x()) > 1e-9 * axis.norm())
    c.fail("axis", "expected a direction across the bar (its x component 0), e.g. [0, 0, 1]");
  shape.axis = axis.normalized();
  return shape;
}

Json body(const std::string& name, const std::string& parent, Json joint, Json elements) {
  Json b = {{"name", name}, {"parent", parent}, {"joint", std::move(joint)}};
  if (!elements.empty()) b["elements"] = std::move(elements);
  return b;
}

Json one_rate_joint(const std::string& name, const char* type, const Vec3& axis, double k, double c,
                    Json origin, double sample_range) {
  // No actuator drives a bar's strain: its rates are left out of τ = S u (docs/control.md).
  Json j = {{"name", name},      {"type", type},
            {"axis", vec(axis)}, {"spring", {{"stiffness", k}}},
            {"actuated", false}, {"sample_range", sample_range}};
  if (c > 0) j["damping"] = c;
  if (!origin.is_null()) j["origin"] = std::move(origin);
  return j;
}

}  // namespace

FlexibleBarParts flexible_bar_parts(const Params& p) {
  p.allow_only({"name", "parent", "origin", "length", "segments", "section", "axial", "torsion",
                "damping", "curvature"});
  const std::string name = p.string("name"), parent = p.string("parent");
  const double L = p.positive("length");
  if (!p.has("segments")) p.fail("segments", "is missing");
  const Json& jn = p.json().at("segments");
  if (!jn.is_number_integer() || jn.get<long long>() < 1 || jn.get<long long>() > kMaxBodies / 4)
    p.fail("segments", "expected an integer from 1 to " + std::to_string(kMaxBodies / 4));
  const int n = jn.get<int>();
  const bool axial = p.boolean_or("axial", true), torsion = p.boolean_or("torsion", true);
  const Section s = read_section(p.child("section"), axial, torsion);
  const RestShape shape = read_rest_shape(p);
  const Damping damping = read_damping(p);
  const double beta = damping.stiffness_proportional;  // c = β k beside every spring
  Json clamp = {{"name", name + ".0"}, {"type", "fixed"}};
  if (p.has("origin")) clamp["origin"] = p.json().at("origin");
  const double delta = L / n;
  Json bodies = Json::array({body(name + ".0", parent, clamp, piece(s, shape, delta / 2))});
  BarSpec bar{.name = name,
              .radius = std::sqrt((s.rhoIy + s.rhoIz) / s.rhoA),
              .mass_proportional = damping.mass_proportional,
              .modal = damping.modal,
              .where = p.where()};
  for (int i = 1; i <= n; ++i) {
    const std::string at = name + "." + std::to_string(i),
                      previous = name + "." + std::to_string(i - 1);
    const double before = i == 1 ? delta / 2 : delta;  // the arc from the previous piece's origin
    struct Rate {
      const char* suffix;
      const char* type;
      Vec3 axis;
      double k;
      bool used;
      double sample_range;
    };
    // Random states (check, stress) keep the bar at small strains: 0.05 rad a part in bending
    // and torsion, a stretch of 1e-3 (a metal's elastic range: 6061-T6 yields at 4e-3). The
    // ±π and ±0.5 m of free joints would fold and invert it.
    const Rate rates[] = {{"ry", "revolute", Vec3::UnitY(), s.EIy / delta, true, 0.05},
                          {"rz", "revolute", Vec3::UnitZ(), s.EIz / delta, true, 0.05},
                          {"rx", "revolute", Vec3::UnitX(), s.GJ / delta, torsion, 0.05},
                          {"ux", "prismatic", Vec3::UnitX(), s.EA / delta, axial, 1e-3 * delta}};
    std::string chain = previous;
    Json at_origin = origin(shape, before);
    for (const Rate& r : rates) {
      if (!r.used) continue;
      const std::string joint = at + "." + r.suffix;
      bar.joints.push_back(joint);
      const bool last = &r == &rates[axial     ? 3
                                     : torsion ? 2
                                               : 1];  // the piece hangs from the last rate
      bodies.push_back(
          body(last ? at : joint, chain,
               one_rate_joint(joint, r.type, r.axis, r.k, beta * r.k, at_origin, r.sample_range),
               last ? piece(s, shape, i == n ? delta / 2 : delta) : Json::array()));
      chain = joint;
      at_origin = nullptr;
    }
  }
  bodies.push_back(
      body(name + ".tip", name + "." + std::to_string(n),
           {{"name", name + ".tip"}, {"type", "fixed"}, {"origin", origin(shape, delta / 2)}},
           Json::array()));
  for (int i = 0; i <= n; ++i) bar.stations.push_back(name + "." + std::to_string(i));
  bar.stations.push_back(name + ".tip");
  return {std::move(bodies), std::move(bar)};
}

}  // namespace femdyn
