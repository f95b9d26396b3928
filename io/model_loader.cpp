#include "io/model_loader.hpp"

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "compile/compile.hpp"
#include "core/limits.hpp"
#include "core/names.hpp"
#include "io/catalog.hpp"
#include "io/input_file.hpp"
#include "io/mjcf_loader.hpp"
#include "io/params.hpp"
#include "io/urdf_loader.hpp"

namespace femdyn {
namespace {

std::string line_col(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

// What one linear pass over a JSON text tells before it is parsed: whether it nests deeper
// than kMaxNesting, and how many items its top-level "bodies" array holds. nlohmann's parser
// with a callback (the earlier depth check) rescans the enclosing array at every object it
// closes, which is quadratic in long arrays of objects; this scan and a plain parse are linear.
struct JsonOutline {
  bool too_deep = false;
  std::size_t bodies = 0;  // items of the top-level "bodies" array (0: none, or not an array)
};

// The index just past the string whose opening quote is text[i], escapes respected.
std::size_t past_string(const std::string& text, std::size_t i) {
  for (++i; i < text.size(); ++i) {
    if (text[i] == '\\')
      ++i;  // (the escaped character, a quote included)
    else if (text[i] == '"')
      return i + 1;
  }
  return text.size();
}

JsonOutline outline(const std::string& text) {
  JsonOutline out;
  int depth = 0;            // containers open
  bool bodies_key = false;  // at depth 1, the last token was the string "bodies" (or its ':')
  bool in_bodies = false;   // inside the top-level "bodies" array (a later one replaces it)
  bool counted = false;     // its current item is counted (until the next ',')
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    if (in_bodies && depth == 2 && c != ']') {
      if (c != ',' && !counted) ++out.bodies;  // an item begins
      counted = c != ',';
    }
    if (c == '"') {
      const std::size_t end = past_string(text, i);
      if (depth == 1) bodies_key = text.compare(i, end - i, "\"bodies\"") == 0;
      i = end;
      continue;
    }
    if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) return {.too_deep = true};
      if (depth == 2 && c == '[' && bodies_key) {
        in_bodies = true;
        counted = false;
        out.bodies = 0;
      }
    } else if (c == ']' || c == '}') {
      if (--depth == 1) in_bodies = false;
    }
    if (c != ':') bodies_key = false;  // the key is "bodies" only when ':' follows it
    ++i;
  }
  return out;
}

JointType joint_type(const Params& p) {
  const std::string t = p.string("type");
  if (const auto type = joint_type_named(t)) return *type;
  p.fail("type", "unknown joint type " + quoted_text(t) + " (expected " + joint_type_list() + ")");
}

// The joint's actuator, friction and stop (docs/model-format.md); compile checks their ranges.
void read_actuator(const Params& p, JointSpec& j) {
  if (p.has("armature")) j.armature = p.non_negative("armature");
  if (p.has("gear")) j.gear = p.number("gear");
  if (p.has("friction")) j.friction = p.non_negative("friction");
  if (p.has("friction_velocity")) j.friction_velocity = p.positive("friction_velocity");
  if (p.has("effort_limit")) j.effort_limit = p.positive("effort_limit");
  if (p.has("velocity_limit")) j.velocity_limit = p.positive("velocity_limit");
  if (p.has("actuated")) j.actuated = p.boolean_or("actuated", true);
  if (p.has("stop")) {
    const Params s = p.child("stop");
    s.allow_only({"stiffness", "dissipation"});
    j.stop = true;
    if (s.has("stiffness")) j.stop_stiffness = s.positive("stiffness");
    if (s.has("dissipation")) j.stop_dissipation = s.non_negative("dissipation");
    if (!p.has("limits")) p.fail("stop", "a stop needs the joint's limits [lower, upper]");
  }
}

JointSpec read_joint(const Params& p) {
  p.allow_only({"name", "type", "origin", "axis", "axis2", "pitch", "limits", "spring", "damping",
                "armature", "gear", "friction", "friction_velocity", "effort_limit",
                "velocity_limit", "stop", "initial", "actuated"});
  JointSpec j;
  j.where = p.where();
  j.name = p.has("name") ? p.string("name") : "";
  j.type = joint_type(p);
  if (p.has("origin")) {
    const Params o = p.child("origin");
    o.allow_only({"xyz", "rpy", "quat"});
    j.xyz = o.vec3_or("xyz", Vec3::Zero());
    j.rpy = o.vec3_or("rpy", Vec3::Zero());
    if (o.has("quat")) {
      if (o.has("rpy")) o.fail("quat", "give the orientation as rpy or as quat, not both");
      const Json& w = o.json()["quat"];
      if (!w.is_array() || w.size() != 4) o.fail("quat", "expected 4 numbers [w, x, y, z]");
      j.quat.emplace();
      for (int k = 0; k < 4; ++k)
        (*j.quat)[k] = json_number(w[k], o.path("quat") + "/" + std::to_string(k));
    }
  }
  const bool any_axis = j.type == JointType::Spherical || j.type == JointType::Free;
  if (any_axis && p.has("axis"))
    p.fail("axis", "a spherical or free joint turns about every axis: it takes no axis");
  if (j.type != JointType::Fixed && !any_axis) j.axis = p.vec3("axis");
  if (p.has("axis2")) j.axis2 = p.vec3("axis2");  // (compile: universal only)
  if (j.type == JointType::Helical)
    j.pitch = p.number("pitch");
  else if (p.has("pitch"))
    p.fail("pitch", "only a helical joint has a pitch");
  if (j.type == JointType::Fixed)
    for (const char* key : {"axis", "limits", "spring", "damping"})
      if (p.has(key))
        p.fail(key, "a fixed joint has no motion: no axis, limits, spring or damping");
  if (p.has("initial")) j.initial = p.number("initial");  // (compile: joints of one coordinate)
  if (j.type == JointType::Fixed)
    for (const char* key : {"armature", "gear", "friction", "friction_velocity", "effort_limit",
                            "velocity_limit", "stop", "actuated"})
      if (p.has(key)) p.fail(key, "a fixed joint has no motion: no actuator, friction or stop");
  if (p.has("limits")) {
    const Json& l = p.json().at("limits");
    if (!l.is_array() || l.size() != 2) p.fail("limits", "expected [lower, upper]");
    j.lower = json_number(l[0], p.path("limits") + "/0");
    j.upper = json_number(l[1], p.path("limits") + "/1");
  }
  if (p.has("spring")) {
    const Params s = p.child("spring");
    s.allow_only({"stiffness", "rest"});
    j.stiffness = s.non_negative("stiffness");
    j.rest = s.number_or("rest", 0.0);
  }
  if (p.has("damping")) j.damping = p.non_negative("damping");
  read_actuator(p, j);
  return j;
}

// Every body's named nodes as "body/node" (body frame of that body): an element may reach a
// node of another body by that name (an element that spans bodies, docs/model-format.md).
std::map<std::string, Vec3> qualified_nodes(const Json& bodies) {
  std::map<std::string, Vec3> all;
  for (const Json& jb : bodies) {
    if (!jb.is_object() || !jb.contains("nodes") || !jb["nodes"].is_object() ||
        !jb.contains("name") || !jb["name"].is_string())
      continue;  // (reported where the body is read)
    const std::string name = jb["name"].get<std::string>();
    for (auto it = jb["nodes"].begin(); it != jb["nodes"].end(); ++it)
      if (it.value().is_array() && it.value().size() == 3 && it.value()[0].is_number() &&
          it.value()[1].is_number() && it.value()[2].is_number())
        all[name + "/" + it.key()] = {it.value()[0].get<double>(), it.value()[1].get<double>(),
                                      it.value()[2].get<double>()};
  }
  return all;
}

BodySpec read_body(const Catalog& catalog, const Json& jb, const std::string& where,
                   const std::map<std::string, Vec3>& other_nodes) {
  const Params p(jb, where);
  p.allow_only({"name", "parent", "joint", "nodes", "elements"});
  BodySpec b;
  b.where = where;
  b.name = p.string("name");
  b.parent = p.string("parent");
  b.joint = read_joint(p.child("joint"));
  std::map<std::string, Vec3> nodes;  // this body's by name ("body/node" in other_nodes)
  if (p.has("nodes")) {
    const Json& jn = jb.at("nodes");
    if (!jn.is_object()) p.fail("nodes", "expected an object {name: [x, y, z]}");
    for (auto it = jn.begin(); it != jn.end(); ++it)
      nodes[it.key()] = json_vec3(it.value(), p.path("nodes") + "/" + it.key());
  }
  if (p.has("elements")) {
    const Json& je = jb.at("elements");
    if (!je.is_array()) p.fail("elements", "expected an array");
    for (std::size_t e = 0; e < je.size(); ++e) {
      const Params ep(je[e], p.path("elements") + "/" + std::to_string(e), b.name, &nodes,
                      &other_nodes);
      const std::string type = ep.string("type");
      const ElementType* t = catalog.elements.find(type);
      if (!t)
        ep.fail("type", "unknown element type " + quoted_text(type) +
                            " (known: " + catalog.elements.names() + ")");
      ElementSink sink(b.elements, ep.where());
      t->make(ep, sink);
    }
  }
  return b;
}

// A nonlinear law: "polynomial", "spline" or "four_bar" (docs/model-format.md#couplings).
std::shared_ptr<const CouplingFunction> read_law(const Params& p, int arity) {
  const auto numbers = [&](const Json& row, const std::string& where) {
    if (!row.is_array()) throw ModelError(where, "expected an array of numbers");
    std::vector<double> v;
    for (std::size_t i = 0; i < row.size(); ++i)
      v.push_back(json_number(row[i], where + "/" + std::to_string(i)));
    return v;
  };
  if (p.has("polynomial")) {
    // [[c, p_1, …, p_k], …]: c Π θ_i^{p_i}
    const Json& terms = p.json().at("polynomial");
    if (!terms.is_array() || terms.empty())
      p.fail("polynomial", "expected a non-empty array of [coefficient, power per joint]");
    std::vector<PolynomialCoupling::Term> list;
    for (std::size_t t = 0; t < terms.size(); ++t) {
      const std::string where = p.path("polynomial") + "/" + std::to_string(t);
      const std::vector<double> v = numbers(terms[t], where);
      if (static_cast<int>(v.size()) != arity + 1)
        throw ModelError(where, "expected [coefficient, " + std::to_string(arity) +
                                    " power(s)]: one power per followed joint");
      PolynomialCoupling::Term term{v[0], {}};
      check_magnitude(v[0], where + "/0", "coefficient");
      for (int k = 1; k <= arity; ++k) {
        if (!(v[k] >= 0 && v[k] <= 16 && v[k] == std::floor(v[k])))
          throw ModelError(where + "/" + std::to_string(k), "a power is an integer from 0 to 16");
        term.powers.push_back(static_cast<int>(v[k]));
      }
      list.push_back(std::move(term));
    }
    return std::make_shared<PolynomialCoupling>(arity, std::move(list));
  }
  if (arity != 1) p.fail("follows", "a spline or four-bar law follows exactly one joint");
  if (p.has("spline")) {
    // [[θ_in, θ_out], …], θ_in strictly increasing
    const Json& pts = p.json().at("spline");
    if (!pts.is_array() || pts.size() < 2)
      p.fail("spline", "expected at least 2 points [θ_in, θ_out]");
    std::vector<double> x, y;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const std::string where = p.path("spline") + "/" + std::to_string(i);
      const std::vector<double> v = numbers(pts[i], where);
      if (v.size() != 2) throw ModelError(where, "expected a point [θ_in, θ_out]");
      check_magnitude(v[0], where + "/0", "θ_in");
      check_magnitude(v[1], where + "/1", "θ_out");
      if (!x.empty() && !(v[0] > x.back()))
        throw ModelError(where + "/0", "θ_in must increase strictly from point to point");
      x.push_back(v[0]);
      y.push_back(v[1]);
    }
    return std::make_shared<SplineCoupling>(std::move(x), std::move(y));
  }
  const Params f = p.child("four_bar");
  f.allow_only({"ground", "input", "coupler", "output", "branch", "input_offset", "input_sign",
                "output_offset", "output_sign"});
  FourBarCoupling::Geometry g;
  g.ground = f.positive("ground");
  g.input = f.positive("input");
  g.coupler = f.positive("coupler");
  g.output = f.positive("output");
  const auto sign = [&](const char* key) {
    const double v = f.number_or(key, 1.0);
    if (v != 1 && v != -1) f.fail(key, "expected 1 or -1");
    return v;
  };
  g.branch = static_cast<int>(sign("branch"));
  g.input_sign = sign("input_sign");
  g.output_sign = sign("output_sign");
  g.input_offset = f.number_or("input_offset", 0.0);
  if (f.has("output_offset")) {
    g.output_offset = f.number("output_offset");
  } else {  // θ_out = 0 where θ_in = 0: ψ0 = ψ(φ0)
    const auto psi0 = FourBarCoupling::output_angle_at_zero(g);
    if (!psi0)
      f.fail("input_offset",
             "the linkage cannot assemble at θ_in = 0, so θ_out = 0 there cannot be the default: "
             "give output_offset");
    g.output_offset = *psi0;
  }
  check_magnitude(g.input_offset, f.path("input_offset"), "input_offset");
  check_magnitude(g.output_offset, f.path("output_offset"), "output_offset");
  for (double len : {g.ground, g.input, g.coupler, g.output})
    check_magnitude(len, f.where(), "link length");
  return std::make_shared<FourBarCoupling>(g);
}

// "follows": f with "ratio": k, or "follows": [{"joint": f1, "ratio": k1}, …] (a linear
// coupling's, or a gear constraint's, terms).
std::vector<std::pair<std::string, double>> read_linear_terms(const Params& p) {
  std::vector<std::pair<std::string, double>> terms;
  const Json& f = p.json().contains("follows") ? p.json().at("follows") : Json();
  if (f.is_string()) {
    terms.emplace_back(f.get<std::string>(), p.number_or("ratio", 1.0));
  } else if (f.is_array()) {
    if (p.has("ratio")) p.fail("ratio", "give ratios inside \"follows\" when it is a list");
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Params t(f[i], p.path("follows") + "/" + std::to_string(i));
      t.allow_only({"joint", "ratio"});
      terms.emplace_back(t.string("joint"), t.number("ratio"));
    }
  } else {
    p.fail("follows", "expected a joint name or a list of {joint, ratio}");
  }
  return terms;
}

CouplingSpec read_coupling(const Params& p) {
  // {"joint": j, "follows": f, "ratio": k, "offset": o}
  // or {"joint": j, "follows": [{"joint": f1, "ratio": k1}, …], "offset": o}
  // or {"joint": j, "follows": f or [f1, f2, …], "polynomial" | "spline" | "four_bar": …}
  p.allow_only({"joint", "follows", "ratio", "offset", "polynomial", "spline", "four_bar"});
  CouplingSpec c;
  c.where = p.where();
  c.joint = p.string("joint");
  const Json& f = p.json().contains("follows") ? p.json().at("follows") : Json();
  int laws = 0;
  for (const char* key : {"polynomial", "spline", "four_bar"}) laws += p.has(key) ? 1 : 0;
  if (laws > 1) p.fail("follows", "give one law: polynomial, spline or four_bar");
  if (laws == 1) {
    for (const char* key : {"ratio", "offset"})
      if (p.has(key)) p.fail(key, "belongs to a linear coupling, not to a law");
    if (f.is_string()) {
      c.follows.push_back(f.get<std::string>());
    } else if (f.is_array() && !f.empty()) {
      for (std::size_t i = 0; i < f.size(); ++i) {
        if (!f[i].is_string())
          throw ModelError(p.path("follows") + "/" + std::to_string(i), "expected a joint name");
        c.follows.push_back(f[i].get<std::string>());
      }
    } else {
      p.fail("follows", "expected a joint name or a non-empty list of joint names");
    }
    c.law = read_law(p, static_cast<int>(c.follows.size()));
    return c;
  }
  c.offset = p.number_or("offset", 0.0);
  c.terms = read_linear_terms(p);
  return c;
}

// The bodies' JSON objects by name (a list: a duplicate name is reported by compile()).
using BodiesByName = std::map<std::string, std::vector<const Json*>>;

BodiesByName bodies_by_name(const Json& bodies) {
  BodiesByName by_name;
  for (const Json& b : bodies)
    if (b.is_object() && b.contains("name") && b["name"].is_string())
      by_name[b["name"].get<std::string>()].push_back(&b);
  return by_name;
}

// A point on `body` (body frame): the node named by p's "node", or p's `point_key` (default 0);
// the two exclude each other.
Vec3 point_on_body(const Params& p, const std::string& body, const BodiesByName& bodies,
                   const char* point_key) {
  if (p.has("node") && p.has(point_key))
    p.fail(point_key, std::string("give either ") + point_key + " or node, not both");
  if (!p.has("node")) return p.vec3_or(point_key, Vec3::Zero());
  std::map<std::string, Vec3> nodes;
  const auto named = bodies.find(body);
  if (named != bodies.end())
    for (const Json* b : named->second)
      if (b->contains("nodes") && (*b)["nodes"].is_object())
        for (auto it = (*b)["nodes"].begin(); it != (*b)["nodes"].end(); ++it)
          nodes[it.key()] = json_vec3(it.value(), p.path("node"));
  const Params np(p.json(), p.where(), body, &nodes);
  return np.node("node").position;
}

// One end of a constraint or spring: "frame, body or world", or {"body", "xyz" | "node", "rpy"}.
AttachmentSpec read_attachment(const Params& p, const char* key, const BodiesByName& bodies) {
  AttachmentSpec a;
  a.where = p.path(key);
  if (!p.has(key)) p.fail(key, "missing (a frame, a body, \"world\", or {\"body\", \"xyz\"})");
  const Json& j = p.json().at(key);
  if (j.is_string()) {
    a.frame = j.get<std::string>();
    return a;
  }
  if (!j.is_object())
    p.fail(key, "expected a frame name or {\"body\", \"xyz\" | \"node\", \"rpy\"}");
  const Params e(j, a.where);
  e.allow_only({"body", "xyz", "node", "rpy"});
  a.body = e.string("body");
  a.xyz = point_on_body(e, a.body, bodies, "xyz");
  a.rpy = e.vec3_or("rpy", Vec3::Zero());
  return a;
}

// {"name", "type", "a", "b", "normal" | "direction" | "length"} or a gear {"name", "type":
// "gear", "joint", "follows", "ratio", "offset"} (docs/model-format.md#constraints).
ConstraintSpec read_constraint(const Params& p, const BodiesByName& bodies, std::size_t index) {
  ConstraintSpec c;
  c.where = p.where();
  c.name = p.has("name") ? p.string("name") : "constraint_" + std::to_string(index);
  c.type = p.string("type");
  if (c.type == "gear") {
    p.allow_only({"name", "type", "joint", "follows", "ratio", "offset"});
    c.joint = p.string("joint");
    c.terms = read_linear_terms(p);
    c.offset = p.number_or("offset", 0.0);
    return c;
  }
  const char* axis_key = c.type == "point_on_line" ? "direction" : "normal";
  if (c.type == "distance")
    p.allow_only({"name", "type", "a", "b", "length"});
  else if (c.type == "weld")
    p.allow_only({"name", "type", "a", "b"});
  else
    p.allow_only({"name", "type", "a", "b", axis_key});
  c.a = read_attachment(p, "a", bodies);
  c.b = read_attachment(p, "b", bodies);
  if (p.has(axis_key)) c.axis = p.vec3(axis_key);
  if (c.type == "distance") c.length = p.positive("length");
  return c;
}

// {"name", "a", "b", "stiffness", "rest_length", "damping"}: a two-point spring-damper.
SpringSpec read_spring(const Params& p, const BodiesByName& bodies, std::size_t index) {
  p.allow_only({"name", "a", "b", "stiffness", "rest_length", "damping"});
  SpringSpec s;
  s.where = p.where();
  s.name = p.has("name") ? p.string("name") : "spring_" + std::to_string(index);
  s.a = read_attachment(p, "a", bodies);
  s.b = read_attachment(p, "b", bodies);
  s.stiffness = p.non_negative("stiffness");
  s.rest_length = p.has("rest_length") ? p.non_negative("rest_length") : 0.0;
  s.damping = p.has("damping") ? p.non_negative("damping") : 0.0;
  return s;
}

// {"name", "body", "xyz" | "node", "rpy"}: a frame on a body, at a point or at one of its nodes.
FrameSpec read_frame(const Params& p, const BodiesByName& bodies) {
  p.allow_only({"name", "body", "xyz", "node", "rpy"});
  FrameSpec f;
  f.where = p.where();
  f.name = p.string("name");
  f.body = p.string("body");
  f.xyz = point_on_body(p, f.body, bodies, "xyz");
  f.rpy = p.vec3_or("rpy", Vec3::Zero());
  return f;
}

LoadSpec read_load(const Params& p, const BodiesByName& bodies) {
  p.allow_only({"body", "point", "node", "force", "torque"});
  LoadSpec l;
  l.where = p.where();
  l.body = p.string("body");
  l.point = point_on_body(p, l.body, bodies, "point");
  l.force = p.vec3_or("force", Vec3::Zero());
  l.torque = p.vec3_or("torque", Vec3::Zero());
  return l;
}

// {"model": NAME, "params": {…}, "name", "description", "gravity", "loads"}: the plugin writes
// the bodies (and couplings, loads, table); the file's own name, gravity and loads apply on top.
MechanismSpec parse_document(const Catalog& catalog, const Json& root, const std::string& source);

// {"model": "urdf", "params": {"file": F, "root_joint": "fixed" | "free"}, …}: a URDF by
// reference (F relative to the JSON file), read from a file only (read_spec, model_document);
// {"model": "mjcf", "params": {"file": F}} an MJCF file the same way.
constexpr const char* kUrdfReference = "urdf";
constexpr const char* kMjcfReference = "mjcf";

// The file's own name, description, gravity and loads on top of the document it expands to.
void apply_overrides(const Json& root, const Params& p, Json& doc) {
  for (const char* key : {"name", "description", "gravity"})
    if (root.contains(key)) doc[key] = root[key];
  for (const char* list : {"loads", "frames", "constraints", "springs"})
    if (root.contains(list)) {
      if (!root[list].is_array()) p.fail(list, "expected an array");
      if (!doc.contains(list)) doc[list] = Json::array();
      for (const Json& l : root[list]) doc[list].push_back(l);
    }
}

// {"model", "params", …}: the keys of a plugin's (or a URDF reference's) form, checked.
Params plugin_form(const Json& root, const std::string& source) {
  Params p(root, source + ": ");
  p.allow_only({"model", "params", "name", "description", "gravity", "loads", "frames",
                "constraints", "springs", "$schema"});
  return p;
}

Json expand_plugin(const Catalog& catalog, const Json& root, const std::string& source) {
  const Params p = plugin_form(root, source);
  const std::string name = p.string("model");
  if (name == kUrdfReference || name == kMjcfReference)
    p.fail("model", "\"" + name + "\" names a file relative to this one: load it from a file");
  const ModelPlugin* plugin = catalog.plugins.find(name);
  if (!plugin) {
    const std::string known = catalog.plugins.names();
    p.fail("model", "unknown model plugin " + quoted_text(name) + " (known: " + known +
                        (known.empty() ? "" : ", ") + kUrdfReference + ", " + kMjcfReference + ")");
  }
  static const Json empty = Json::object();
  Json doc = plugin->expand(p.has("params") ? p.child("params") : Params(empty, p.path("params")));
  apply_overrides(root, p, doc);
  return doc;
}

MechanismSpec parse_document(const Catalog& catalog, const Json& root, const std::string& source) {
  MechanismSpec spec;
  spec.where = source + ": ";
  const auto path = [&](const std::string& s) { return source + ": /" + s; };
  for (auto it = root.begin(); it != root.end(); ++it) {
    static const char* known[] = {
        "name",        "description", "gravity",           "bodies", "couplings", "loads", "frames",
        "constraints", "springs",     "correlation_table", "$schema"};
    bool ok = false;
    for (const char* k : known) ok = ok || it.key() == k;
    if (!ok) throw ModelError(path(truncated(it.key())), "unknown key " + quoted_text(it.key()));
  }
  if (root.contains("name")) {
    if (!root["name"].is_string()) throw ModelError(path("name"), "expected a string");
    spec.name = root["name"].get<std::string>();
  }
  if (root.contains("gravity")) spec.gravity = json_vec3(root["gravity"], path("gravity"));
  if (!root.contains("bodies") || !root["bodies"].is_array())
    throw ModelError(path("bodies"), "expected an array of bodies");
  const Json& bodies = root["bodies"];
  if (bodies.size() > static_cast<std::size_t>(kMaxBodies))  // before anything is built for them
    throw ModelError(path("bodies"), too_many_bodies_text(bodies.size()));
  const std::map<std::string, Vec3> qualified = qualified_nodes(bodies);
  for (std::size_t i = 0; i < bodies.size(); ++i)
    spec.bodies.push_back(
        read_body(catalog, bodies[i], path("bodies/" + std::to_string(i)), qualified));
  if (root.contains("couplings")) {
    if (!root["couplings"].is_array()) throw ModelError(path("couplings"), "expected an array");
    for (std::size_t i = 0; i < root["couplings"].size(); ++i)
      spec.couplings.push_back(
          read_coupling(Params(root["couplings"][i], path("couplings/" + std::to_string(i)))));
  }
  if (root.contains("loads")) {
    if (!root["loads"].is_array()) throw ModelError(path("loads"), "expected an array");
    const BodiesByName by_name = bodies_by_name(bodies);
    for (std::size_t i = 0; i < root["loads"].size(); ++i)
      spec.loads.push_back(
          read_load(Params(root["loads"][i], path("loads/" + std::to_string(i))), by_name));
  }
  if (root.contains("frames")) {
    if (!root["frames"].is_array()) throw ModelError(path("frames"), "expected an array");
    const BodiesByName by_name = bodies_by_name(bodies);
    for (std::size_t i = 0; i < root["frames"].size(); ++i)
      spec.frames.push_back(
          read_frame(Params(root["frames"][i], path("frames/" + std::to_string(i))), by_name));
  }
  for (const char* list : {"constraints", "springs"}) {
    if (!root.contains(list)) continue;
    if (!root[list].is_array()) throw ModelError(path(list), "expected an array");
    const BodiesByName by_name = bodies_by_name(bodies);
    for (std::size_t i = 0; i < root[list].size(); ++i) {
      const Params item(root[list][i], path(std::string(list) + "/" + std::to_string(i)));
      if (std::string(list) == "constraints")
        spec.constraints.push_back(read_constraint(item, by_name, i));
      else
        spec.springs.push_back(read_spring(item, by_name, i));
    }
  }
  if (root.contains("correlation_table")) {
    // [[…], …]  or  {"rows": [[…], …], "join": "same" | "deepest"}
    const Json* tp = &root["correlation_table"];
    CorrelationSpec cs;
    cs.where = path("correlation_table");
    if (tp->is_object()) {
      const Params tparams(*tp, cs.where);
      tparams.allow_only({"rows", "join"});
      const std::string join = tparams.has("join") ? tparams.string("join") : "same";
      if (join != "same" && join != "deepest")
        tparams.fail("join", "expected \"same\" or \"deepest\", got \"" + join + "\"");
      cs.join_deepest = join == "deepest";
      if (!tp->contains("rows")) tparams.fail("rows", "is missing");
      tp = &tp->at("rows");
      cs.where += "/rows";
    }
    const Json& t = *tp;
    if (!t.is_array()) throw ModelError(cs.where, "expected an array of rows");
    for (std::size_t r = 0; r < t.size(); ++r) {
      const std::string w = cs.where + "/" + std::to_string(r);
      if (!t[r].is_array()) throw ModelError(w, "expected an array of integers");
      std::vector<int> row;
      for (std::size_t k = 0; k < t[r].size(); ++k) {
        const Json& x = t[r][k];
        const std::string wk = w + "/" + std::to_string(k);
        if (!x.is_number_integer()) throw ModelError(wk, "expected an integer DOF number");
        // Range-checked before narrowing: 2^31 must not wrap to a negative int, nor 2^63 to 0.
        const bool fits = x.is_number_unsigned()
                              ? x.get<std::uint64_t>() <= 2147483647u
                              : x.get<std::int64_t>() >= 0 && x.get<std::int64_t>() <= 2147483647;
        if (!fits)
          throw ModelError(wk, "DOF number " + x.dump() + " is out of range (0 to 2147483647)");
        row.push_back(x.get<int>());
      }
      cs.rows.push_back(std::move(row));
    }
    spec.correlation = std::move(cs);
  }
  return spec;
}

}  // namespace

CouplingSpec parse_coupling(const Json& coupling, const std::string& where) {
  return read_coupling(Params(coupling, where));
}

ConstraintSpec parse_constraint(const Json& constraint, const std::string& where,
                                std::size_t index) {
  return read_constraint(Params(constraint, where), {}, index);
}

SpringSpec parse_spring(const Json& spring, const std::string& where, std::size_t index) {
  return read_spring(Params(spring, where), {}, index);
}

namespace {

// The text as JSON, its nesting and body count bounded first; malformed JSON named by line and
// column.
Json parse_json(const std::string& text, const std::string& source) {
  // The nesting depth and the number of bodies are bounded (core/limits.hpp) by one pass over
  // the text, before a deep or huge document can cost anything.
  const JsonOutline shape = outline(text);
  if (shape.too_deep)
    throw ModelError(source, "JSON nested deeper than " + std::to_string(kMaxNesting) +
                                 " levels (femdyn's limit)");
  if (shape.bodies > static_cast<std::size_t>(kMaxBodies))
    throw ModelError(source + ": /bodies", too_many_bodies_text(shape.bodies));
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    std::string what = e.what();
    const auto colon = what.rfind(": ");
    throw ModelError(source, "malformed JSON at " + line_col(text, e.byte == 0 ? 0 : e.byte - 1) +
                                 (colon == std::string::npos ? "" : ": " + what.substr(colon + 2)));
  } catch (const Json::exception& e) {  // e.g. number overflow (1e999)
    std::string what = e.what();
    const auto bracket = what.find("] ");
    throw ModelError(source, "malformed JSON: " +
                                 (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  }
  return root;
}

}  // namespace

MechanismSpec parse_spec(const std::string& text, const std::string& source,
                         const Catalog& catalog) {
  return parse_model_json(parse_json(text, source), source, catalog);
}

MechanismSpec parse_model_json(const Json& root, const std::string& source,
                               const Catalog& catalog) {
  if (!root.is_object()) throw ModelError(source, "expected a JSON object at the top level");
  if (root.contains("model"))
    return parse_document(catalog, expand_plugin(catalog, root, source), source);
  return parse_document(catalog, root, source);
}

namespace {

std::string read_text(const std::string& path) { return read_input_file(path); }

// Errors found after conversion name the robot file's link (MJCF: body) and joint, not the
// generated JSON path: "robot.urdf: /bodies/3/joint: …" becomes "robot.urdf: joint 'elbow'
// (link 'forearm'): …".
[[noreturn]] void rethrow_for_urdf(const ModelError& e, const Json& doc, const std::string& path) {
  const std::string link = is_mjcf_path(path) ? "body" : "link";
  const std::string mimic = is_mjcf_path(path) ? "' <equality>" : "' <mimic>";
  std::string msg = e.what();
  // "/bodies/N…" names a joint and its child link; "/couplings/N…" a joint's <mimic>.
  for (const std::string section : {"bodies", "couplings"}) {
    const std::string prefix = path + ": /" + section + "/";
    if (msg.rfind(prefix, 0) != 0) continue;
    std::size_t i = prefix.size(), end = i;
    while (end < msg.size() && std::isdigit(static_cast<unsigned char>(msg[end]))) ++end;
    const std::size_t rest = msg.find(": ", end);
    if (end == i || rest == std::string::npos) break;
    const Json& item = doc[section][std::stoul(msg.substr(i, end - i))];
    const std::string who = section == "bodies"
                                ? "joint '" + item["joint"]["name"].get<std::string>() + "' (" +
                                      link + " '" + item["name"].get<std::string>() + "')"
                                : "joint '" + item["joint"].get<std::string>() + mimic;
    msg = path + ": " + who + msg.substr(rest);
  }
  throw ModelError("", msg);
}

}  // namespace

namespace {

Json urdf_document(const std::string& urdf, UrdfOptions urdf_options, const LoadOptions& options) {
  UrdfResult r = read_urdf(urdf, urdf_options);
  if (options.warn)
    for (const std::string& w : r.warnings) options.warn(w);
  return std::move(r.model);
}

Json mjcf_document(const std::string& mjcf, MjcfOptions mjcf_options, const LoadOptions& options) {
  MjcfResult r = read_mjcf(mjcf, mjcf_options);
  if (options.warn)
    for (const std::string& w : r.warnings) options.warn(w);
  return std::move(r.model);
}

// A URDF or MJCF file as femdyn JSON. --floating-base is for URDF: MJCF floats a body by its own
// free joint.
Json robot_document(const std::string& path, const LoadOptions& options) {
  if (is_urdf_path(path))
    return urdf_document(
        path, {.floating_base = options.floating_base, .balance_inertia = options.balance_inertia},
        options);
  if (options.floating_base)
    throw ModelError(path,
                     "--floating-base is for URDF models: an MJCF model floats a body by its "
                     "own <freejoint/>");
  return mjcf_document(path,
                       {.balance_inertia = options.balance_inertia,
                        .exact_mesh_inertia = options.exact_mesh_inertia},
                       options);
}

// {"model": "mjcf", "params": {"file", "balance_inertia"}}: the MJCF file it names, with the
// reference's own name, description, gravity and loads.
std::pair<Json, std::string> mjcf_reference(const std::string& path, const Json& root,
                                            const Params& p, const Params& params,
                                            const LoadOptions& options) {
  params.allow_only({"file", "balance_inertia"});
  std::filesystem::path file(params.string("file"));
  if (file.is_relative()) file = std::filesystem::path(path).parent_path() / file;
  if (!is_mjcf_path(file.string())) params.fail("file", "expected an MJCF file (<mujoco>)");
  Json doc;
  try {
    doc = mjcf_document(
        file.string(),
        {.balance_inertia = options.balance_inertia || params.boolean_or("balance_inertia", false)},
        options);
  } catch (const Error& e) {
    params.fail("file", e.what());
  }
  apply_overrides(root, p, doc);
  return {std::move(doc), file.string()};
}

// A JSON file {"model": "urdf", …}: the URDF it names as femdyn JSON (with the file's own name,
// description, gravity and loads), and that URDF's path for messages; nullopt for any other file.
std::optional<std::pair<Json, std::string>> urdf_reference(const std::string& path,
                                                           const Json& root,
                                                           const LoadOptions& options) {
  if (!root.is_object() || !root.contains("model") ||
      (root["model"] != kUrdfReference && root["model"] != kMjcfReference))
    return std::nullopt;
  const Params p = plugin_form(root, path);
  const Params params = p.child("params");
  if (root["model"] == kMjcfReference) return mjcf_reference(path, root, p, params, options);
  params.allow_only({"file", "root_joint", "balance_inertia"});
  const std::string root_joint = params.has("root_joint") ? params.string("root_joint") : "fixed";
  if (root_joint != "fixed" && root_joint != "free")
    params.fail("root_joint", "expected \"fixed\" or \"free\", got " + quoted_text(root_joint));
  const std::string file = params.string("file");
  std::filesystem::path urdf(file);
  if (urdf.is_relative()) urdf = std::filesystem::path(path).parent_path() / urdf;
  if (!is_urdf_path(urdf.string())) params.fail("file", "expected a *.urdf file");
  Json doc;
  try {
    doc = urdf_document(
        urdf.string(),
        {.floating_base = root_joint == "free",
         .balance_inertia = options.balance_inertia || params.boolean_or("balance_inertia", false)},
        options);
  } catch (const Error& e) {
    params.fail("file", e.what());
  }
  apply_overrides(root, p, doc);
  return std::pair{std::move(doc), urdf.string()};
}

// --balance-inertia repairs what an exporter wrote; a JSON model's inertias are the author's own,
// refused with the element named, to be corrected there.
void refuse_balance_on_json(const std::string& path, const LoadOptions& options) {
  if (options.balance_inertia)
    throw ModelError(path,
                     "--balance-inertia is for URDF models (and URDF references, \"params\": "
                     "{\"balance_inertia\": true}): a JSON model's inertias are its own, to be "
                     "corrected where a refusal names them");
}

}  // namespace

Json model_document(const std::string& path, const LoadOptions& options) {
  if (is_robot_file(path)) return robot_document(path, options);
  const Json root = parse_json(read_text(path), path);
  if (auto ref = urdf_reference(path, root, options)) return std::move(ref->first);
  refuse_balance_on_json(path, options);
  const Catalog& catalog = options.catalog ? *options.catalog : default_catalog();
  (void)parse_model_json(root, path, catalog);  // reports every model error by its path
  return root.contains("model") ? expand_plugin(catalog, root, path) : root;
}

MechanismSpec read_spec(const std::string& path, const LoadOptions& options) {
  const Catalog& catalog = options.catalog ? *options.catalog : default_catalog();
  if (!is_robot_file(path) && options.floating_base)
    throw ModelError(path,
                     "--floating-base is for URDF models: a JSON model gives its root body a "
                     "free joint itself (\"joint\": {\"type\": \"free\"}), a URDF "
                     "reference by \"root_joint\": \"free\"");
  if (!is_robot_file(path)) {
    const Json root = parse_json(read_text(path), path);
    if (auto ref = urdf_reference(path, root, options)) {
      try {
        return parse_model_json(ref->first, ref->second, catalog);
      } catch (const ModelError& e) {
        rethrow_for_urdf(e, ref->first, ref->second);
      }
    }
    refuse_balance_on_json(path, options);
    return parse_model_json(root, path, catalog);
  }
  const Json doc = model_document(path, options);
  try {
    return parse_model_json(doc, path, catalog);
  } catch (const ModelError& e) {
    rethrow_for_urdf(e, doc, path);
  }
}

Model load_model(const std::string& path, const LoadOptions& options) {
  MechanismSpec spec = read_spec(path, options);
  if (options.gravity) {
    spec.gravity = *options.gravity;
    spec.gravity_where = spec.where + options.gravity_source;  // (where ends in ": ")
  }
  if (!is_robot_file(path)) return compile(std::move(spec), options.compile);
  try {
    return compile(std::move(spec), options.compile);
  } catch (const ModelError& e) {
    rethrow_for_urdf(e, model_document(path, options), path);
  }
}

}  // namespace femdyn
