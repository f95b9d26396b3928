#include "models/dexterous_finger.hpp"

#include <cmath>
#include <numbers>

#include "core/model/coupling_function.hpp"

namespace femdyn {
namespace {

enum class Sign { Positive, NonNegative, Any };

template <std::size_t N>
std::array<double, N> numbers_or(const Params& p, const char* key, std::array<double, N> fallback,
                                 Sign sign) {
  if (!p.has(key)) return fallback;
  const Json& v = p.json().at(key);
  std::array<double, N> out;
  if (v.is_number()) {
    out.fill(json_number(v, p.path(key)));
  } else {
    if (!v.is_array() || v.size() != N)
      p.fail(key, "expected a number or an array of " + std::to_string(N) + " numbers");
    for (std::size_t i = 0; i < N; ++i)
      out[i] = json_number(v[i], p.path(key) + "/" + std::to_string(i));
  }
  for (double x : out) {
    if (sign == Sign::Positive && !(x > 0)) p.fail(key, "must be positive");
    if (sign == Sign::NonNegative && x < 0) p.fail(key, "must not be negative");
  }
  return out;
}

// The paper's correlation table N_m, as printed (4 units x 12).
const int kPaperTable[4][12] = {{0, 0, 0, 0, 0, 1, 2, 3, 0, 4, 0, 0},
                                {2, 3, 0, 4, 0, 0, 5, 6, 7, 8, 0, 0},
                                {5, 6, 7, 8, 0, 0, 9, 10, 11, 12, 0, 0},
                                {9, 10, 11, 12, 0, 0, 13, 14, 15, 16, 0, 0}};

// The four-bar's two lever tips: the input lever's on the proximal phalanx, at the PIP axis
// (`pip`, in the proximal frame), and the output lever's on the distal phalanx, at the DIP axis
// (in the distal frame). The linkage's plane is the flexion plane: a planar angle α from the
// middle phalanx's direction (+z) towards −y is the point (0, −r sin α, r cos α); the proximal
// phalanx turns by −θ3 seen from the middle one and the distal by +θ4, so the law needs
// input_sign −1 and output_sign +1, and its ground is the middle phalanx.
struct Levers {
  Vec3 proximal, distal;
};

Levers four_bar_levers(const FingerParams& f, const Vec3& pip) {
  const Json& g = f.law.at("four_bar");
  const auto number = [&](const char* key, double fallback) {
    return g.contains(key) && g[key].is_number() ? g[key].get<double>() : fallback;
  };
  const double a = number("input", 0), c = number("output", 0);
  const double phi0 = number("input_offset", 0), branch = number("branch", 1);
  double psi0 = number("output_offset", NAN);
  if (std::isnan(psi0))  // the default: θ4 = 0 at θ3 = 0 (0 where it cannot assemble: refused)
    psi0 = FourBarCoupling::output_angle_at_zero({.ground = number("ground", 0),
                                                  .input = a,
                                                  .coupler = number("coupler", 0),
                                                  .output = c,
                                                  .branch = branch < 0 ? -1 : 1,
                                                  .input_offset = phi0})
               .value_or(0.0);
  const auto planar = [](double r, double alpha) {
    return Vec3(0, -r * std::sin(alpha), r * std::cos(alpha));
  };
  return {pip + planar(a, phi0), planar(c, psi0)};
}

Json* find_body(Json& bodies, const std::string& name) {
  for (Json& b : bodies)
    if (b["name"] == name) return &b;
  return nullptr;
}

// Closed by the law: the coupler as a rod spanning the two lever tips (compile() checks that it
// keeps its length).
void append_coupler_rod(const FingerParams& f, const std::string& prefix, const Levers& levers,
                        Json& bodies) {
  Json& proximal = *find_body(bodies, prefix + "proximal");
  find_body(bodies, prefix + "distal")->at("nodes")["lever"] = vec3_json(levers.distal);
  proximal["nodes"]["lever"] = vec3_json(levers.proximal);
  proximal["elements"].push_back(
      {{"type", "rod"}, {"nodes", {"lever", prefix + "distal/lever"}}, {"mass", f.coupler_mass}});
}

// Closed by a constraint (docs/loops.md): the coupler a body of its own on a revolute joint
// "<prefix>coupler" at the input lever's tip, its rod from there to its far end, which a ball in
// the flexion plane (normal x, 2 equations) holds on the output lever's tip. The DIP joint stays a
// coordinate. At q = 0 the loop is closed where the law's zero is (θ4 = 0 at θ3 = 0): the far end
// is the output lever's tip there, on the distal phalanx whose joint is at `dip` (in the proximal
// frame at q = 0).
void append_coupler_loop(const FingerParams& f, const std::string& prefix, const Levers& levers,
                         const Vec3& dip, FingeredParts& parts) {
  find_body(parts.bodies, prefix + "distal")->at("nodes")["lever"] = vec3_json(levers.distal);
  const Vec3 span = dip + levers.distal - levers.proximal;
  parts.bodies.push_back(
      {{"name", prefix + "coupler"},
       {"parent", prefix + "proximal"},
       {"joint",
        {{"name", prefix + "coupler"},
         {"type", "revolute"},
         {"axis", vec3_json(Vec3::UnitX())},
         {"origin", {{"xyz", vec3_json(levers.proximal)}}}}},
       {"nodes", {{"a", vec3_json(Vec3::Zero())}, {"b", vec3_json(span)}}},
       {"elements",
        Json::array({{{"type", "rod"}, {"nodes", {"a", "b"}}, {"mass", f.coupler_mass}}})}});
  parts.frames.push_back(
      {{"name", prefix + "coupler_end"}, {"body", prefix + "coupler"}, {"node", "b"}});
  parts.frames.push_back(
      {{"name", prefix + "distal_lever"}, {"body", prefix + "distal"}, {"node", "lever"}});
  parts.constraints.push_back({{"name", prefix + "coupler_end"},
                               {"type", "ball"},
                               {"a", prefix + "coupler_end"},
                               {"b", prefix + "distal_lever"},
                               {"normal", vec3_json(Vec3::UnitX())}});
}

}  // namespace

FingerParams FingerParams::from(const Params& p) {
  p.allow_only({"lengths", "width", "height", "density", "limits", "stiffness", "rest", "damping",
                "coupling", "tip_force", "lumping"});
  FingerParams f;
  f.length = numbers_or<4>(p, "lengths", f.length, Sign::Positive);
  f.width = numbers_or<4>(p, "width", f.width, Sign::Positive);
  f.height = numbers_or<4>(p, "height", f.height, Sign::Positive);
  if (p.has("density")) f.density = p.positive("density");
  f.stiffness = numbers_or<4>(p, "stiffness", f.stiffness, Sign::NonNegative);
  f.rest = numbers_or<4>(p, "rest", f.rest, Sign::Any);
  f.damping = numbers_or<4>(p, "damping", f.damping, Sign::NonNegative);
  if (p.has("limits")) {
    const Json& l = p.json().at("limits");
    if (!l.is_array() || l.size() != 4) p.fail("limits", "expected 4 pairs [lower, upper]");
    for (int i = 0; i < 4; ++i) {
      const std::string w = p.path("limits") + "/" + std::to_string(i);
      if (!l[i].is_array() || l[i].size() != 2) throw ModelError(w, "expected [lower, upper]");
      f.limits[i] = {json_number(l[i][0], w + "/0"), json_number(l[i][1], w + "/1")};
    }
  }
  if (p.has("coupling") && !p.json().at("coupling").is_null()) {
    const Params c = p.child("coupling");
    c.allow_only(
        {"ratio", "offset", "four_bar", "polynomial", "spline", "coupler_mass", "closure"});
    f.coupled = true;
    f.ratio = c.number_or("ratio", 1.0);
    f.offset = c.number_or("offset", 0.0);
    for (const char* law : {"four_bar", "polynomial", "spline"})
      if (c.has(law)) {
        if (!f.law.is_null()) c.fail(law, "give one law: ratio, four_bar, polynomial or spline");
        if (c.has("ratio") || c.has("offset"))
          c.fail(law, "ratio and offset belong to a linear coupling, not to a law");
        f.law = Json{{law, c.json().at(law)}};
      }
    if (c.has("coupler_mass")) {
      if (!f.law.contains("four_bar")) c.fail("coupler_mass", "belongs to a four_bar coupling");
      f.coupler_mass = c.positive("coupler_mass");
    }
    if (c.has("closure")) {
      const std::string closure = c.string("closure");
      if (closure != "law" && closure != "constraint")
        c.fail("closure", "expected \"law\" or \"constraint\"");
      if (closure == "constraint" && !(f.law.contains("four_bar") && f.coupler_mass > 0))
        c.fail("closure",
               "a loop closed by a constraint needs a four_bar and its coupler_mass (the coupler "
               "is a body of its own, which must have mass)");
      f.closed_by_constraint = closure == "constraint";
    }
  }
  f.tip_force = p.vec3_or("tip_force", Vec3::Zero());
  if (p.has("lumping")) {
    const std::string l = p.string("lumping");
    if (l != "exact" && l != "paper") p.fail("lumping", "expected \"exact\" or \"paper\"");
    f.paper_lumping = l == "paper";
  }
  return f;
}

void append_finger(const FingerParams& f, const std::string& prefix, const std::string& parent,
                   const Vec3& xyz, const Vec3& rpy, FingeredParts& parts) {
  Json& bodies = parts.bodies;
  static const char* body[] = {"base", "proximal", "middle", "distal"};
  static const char* joint[] = {"abduction", "mcp", "pip", "dip"};
  // Unit k runs from its joint to the next: the base radially along −y, knuckles along +z.
  const Vec3 along[] = {Vec3(0, -f.length[0], 0), Vec3(0, 0, f.length[1]), Vec3(0, 0, f.length[2]),
                        Vec3(0, 0, f.length[3])};
  for (int k = 0; k < 4; ++k) {
    Json j = {{"name", prefix + joint[k]},
              {"type", "revolute"},
              {"axis", k == 0 ? vec3_json(Vec3::UnitZ()) : vec3_json(Vec3::UnitX())},
              {"limits", Json::array({f.limits[k][0], f.limits[k][1]})}};
    // Base joint: the mount, then a quarter turn so that the body x is the flexion axis.
    j["origin"] = k == 0 ? Json{{"xyz", vec3_json(xyz)}, {"rpy", vec3_json(rpy)}}
                         : Json{{"xyz", vec3_json(along[k - 1])}};
    if (f.stiffness[k] > 0) j["spring"] = {{"stiffness", f.stiffness[k]}, {"rest", f.rest[k]}};
    if (f.damping[k] > 0) j["damping"] = f.damping[k];
    // Section: width w along the flexion axis (body x), height h across it. In the bar frame
    // (x̂ along the bar, ŷ = section_y) I_y = ∫z² dA, I_z = ∫y² dA.
    const double w = f.width[k], h = f.height[k];
    const bool radial = k == 0;  // base unit: bar along −y, section ŷ = body x, ẑ = body z
    Json bar = {{"type", "space_bar"},
                {"nodes", Json::array({"a", "b"})},
                {"density", f.density},
                {"area", w * h}};
    if (f.paper_lumping) {
      // The paper's lumping in body axes: I_y, I_z as the paper labels them (about body y, z).
      bar["Iy"] = radial ? w * h * h * h / 12 : h * w * w * w / 12;
      bar["Iz"] = radial ? h * w * w * w / 12 : w * h * h * h / 12;
      bar["lumping"] = "paper";
    } else {
      bar["section_y"] = vec3_json(Vec3::UnitX());
      // x̂ × ŷ = ẑ: for the base (x̂ = −y) ẑ = −y × x = z; for knuckles (x̂ = z) ẑ = z × x = y.
      bar["Iy"] = w * h * h * h / 12;  // ∫ z² dA, z (body y) across the height
      bar["Iz"] = h * w * w * w / 12;
    }
    Json b = {{"name", prefix + body[k]},
              {"parent", k == 0 ? parent : prefix + body[k - 1]},
              {"joint", j},
              {"nodes", {{"a", vec3_json(Vec3::Zero())}, {"b", vec3_json(along[k])}}},
              {"elements", Json::array({bar})}};
    bodies.push_back(b);
  }
  if (f.closed_by_constraint) {
    append_coupler_loop(f, prefix, four_bar_levers(f, along[1]), along[1] + along[2], parts);
  } else if (f.coupled && !f.law.is_null()) {
    Json c = f.law;  // the law's key and value, checked when the model is loaded
    c["joint"] = prefix + "dip";
    c["follows"] = prefix + "pip";
    parts.couplings.push_back(c);
    if (f.coupler_mass > 0) append_coupler_rod(f, prefix, four_bar_levers(f, along[1]), bodies);
  } else if (f.coupled) {
    parts.couplings.push_back({{"joint", prefix + "dip"},
                               {"follows", prefix + "pip"},
                               {"ratio", f.ratio},
                               {"offset", f.offset}});
  }
  if (!f.tip_force.isZero(0))
    parts.loads.push_back({{"body", prefix + "distal"},
                           {"point", vec3_json(along[3])},
                           {"force", vec3_json(f.tip_force)}});
}

namespace {

Json tip_frames(const Json& bodies) {
  static const std::string kDistal = "distal";
  Json frames = Json::array();
  for (const Json& b : bodies) {
    const std::string name = b.at("name");
    if (name.size() < kDistal.size() ||
        name.compare(name.size() - kDistal.size(), kDistal.size(), kDistal) != 0)
      continue;
    if (!b.contains("nodes") || !b["nodes"].contains("b")) continue;
    const std::string prefix = name.substr(0, name.size() - kDistal.size());
    frames.push_back({{"name", prefix + "tip"}, {"body", name}, {"node", "b"}});
  }
  return frames;
}

}  // namespace

Json fingered_model(const std::string& name, const FingeredParts& parts) {
  Json model = {{"name", name}, {"bodies", parts.bodies}};
  if (!parts.couplings.empty()) model["couplings"] = parts.couplings;
  if (!parts.loads.empty()) model["loads"] = parts.loads;
  Json frames = tip_frames(parts.bodies);
  for (const Json& frame : parts.frames) frames.push_back(frame);
  if (!frames.empty()) model["frames"] = frames;
  if (!parts.constraints.empty()) model["constraints"] = parts.constraints;
  return model;
}

Json dexterous_finger(const Params& params) {
  const FingerParams f = FingerParams::from(params);
  FingeredParts parts;
  append_finger(f, "", "world", Vec3::Zero(), Vec3(0, 0, std::numbers::pi / 2), parts);
  Json model = fingered_model(
      f.paper_lumping ? "dexterous finger (paper's discretisation)" : "dexterous finger", parts);
  if (f.paper_lumping) {
    if (f.coupled) params.fail("coupling", "the paper's discretisation has 4 independent joints");
    Json rows = Json::array();
    for (const auto& row : kPaperTable) rows.push_back(Json(std::vector<int>(row, row + 12)));
    model["correlation_table"] = {{"rows", rows}, {"join", "deepest"}};
  }
  return model;
}

}  // namespace femdyn
