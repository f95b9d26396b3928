// femdyn JSON (docs/model-format.md) into a MechanismSpec: the document's keys, its bodies with
// their joints and elements, and its lists; the places on bodies are io/json_places.cpp's, the
// front door for files io/model_file.cpp's.
#include "io/model_loader.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/joints/kernel.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "io/catalog.hpp"
#include "io/coupling_json.hpp"
#include "io/flexible_bar.hpp"
#include "io/json_places.hpp"
#include "io/json_text.hpp"
#include "io/params.hpp"
#include "io/robot_reference.hpp"

namespace femdyn {
namespace {

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
  if (p.has("sample_range")) j.sample_range = p.positive("sample_range");
  if (p.has("stop")) {
    const Params s = p.child("stop");
    s.allow_only({"stiffness", "dissipation"});
    j.stop = true;
    if (s.has("stiffness")) j.stop_stiffness = s.positive("stiffness");
    if (s.has("dissipation")) j.stop_dissipation = s.non_negative("dissipation");
    if (!p.has("limits")) p.fail("stop", "a stop needs the joint's limits [lower, upper]");
  }
}

// What the joint's type reads (core/joints/parameters.hpp): its axes, and each of its own
// numbers, which are required; another type's number is refused.
void read_joint_parameters(const Params& p, JointSpec& j) {
  const JointParameters type = joint_parameters(j.type);
  if (type.moves && type.axes == JointAxes::None && p.has("axis"))
    p.fail("axis", joint_axis_refusal(j.type));
  if (type.axes != JointAxes::None) j.axis = p.vec3("axis");
  if (p.has("axis2")) j.axis2 = p.vec3("axis2");  // (compile: a type of two axes only)
  for (const JointScalar& s : type.scalars) {
    const std::string key(s.key);
    j.scalars[key] = p.number(key.c_str());
  }
  for (auto it = p.json().begin(); it != p.json().end(); ++it)
    if (is_joint_scalar(it.key()) && !joint_scalar(j.type, it.key()))
      p.fail(it.key().c_str(), joint_scalar_refusal(it.key()));
}

// {"spin_up": {"rate": ω_s, "time": T_s}} or {"polynomial": [c_0, c_1, …]}
// (core/model/prescribed_motion.hpp).
PrescribedMotion read_prescribed(const Params& p) {
  p.allow_only({"spin_up", "polynomial"});
  PrescribedMotion m;
  if (p.has("spin_up") == p.has("polynomial"))
    p.fail("spin_up",
           "give one motion: {\"spin_up\": {\"rate\", \"time\"}} or "
           "{\"polynomial\": [c0, c1, …]}");
  if (p.has("spin_up")) {
    const Params s = p.child("spin_up");
    s.allow_only({"rate", "time"});
    m.kind = PrescribedMotion::Kind::SpinUp;
    m.rate = s.number("rate");
    m.time = s.positive("time");
    return m;
  }
  const Json& c = p.json().at("polynomial");
  if (!c.is_array() || c.empty() || c.size() > 16)
    p.fail("polynomial", "expected 1 to 16 coefficients [c0, c1, …] (q = Σ c_k t^k)");
  for (std::size_t k = 0; k < c.size(); ++k)
    m.coefficients.push_back(json_number(c[k], p.path("polynomial") + "/" + std::to_string(k)));
  return m;
}

JointSpec read_joint(const Params& p) {
  p.allow_only({"name", "type", "origin", "axis", "axis2", "limits", "spring", "damping",
                "armature", "gear", "friction", "friction_velocity", "effort_limit",
                "velocity_limit", "stop", "initial", "actuated", "prescribed", "sample_range"},
               is_joint_scalar);
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
  read_joint_parameters(p, j);
  if (j.type == JointType::Fixed)
    for (const char* key : {"axis", "limits", "spring", "damping"})
      if (p.has(key))
        p.fail(key, "a fixed joint has no motion: no axis, limits, spring or damping");
  if (p.has("initial")) j.initial = p.number("initial");  // (compile: joints of one coordinate)
  if (j.type == JointType::Fixed)
    for (const char* key : {"armature", "gear", "friction", "friction_velocity", "effort_limit",
                            "velocity_limit", "stop", "actuated", "prescribed", "sample_range"})
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
  if (p.has("prescribed")) j.prescribed = read_prescribed(p.child("prescribed"));
  return j;
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

// {"model": NAME, "params": {…}, "name", "description", "gravity", "loads"}: the plugin writes
// the bodies (and couplings, loads, table); the file's own name, gravity and loads apply on top.
MechanismSpec parse_document(const Catalog& catalog, const Json& root, const std::string& source);

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

// The items of the list root[key] (an array, or absent), each read by `read` from its Params.
template <class Read>
void read_list(const Json& root, const char* key, const std::string& source, Read read) {
  if (!root.contains(key)) return;
  const std::string where = source + ": /" + key;
  if (!root[key].is_array()) throw ModelError(where, "expected an array");
  for (std::size_t i = 0; i < root[key].size(); ++i)
    read(Params(root[key][i], where + "/" + std::to_string(i)), i);
}

// One DOF number of an explicit correlation table, range-checked before narrowing: 2^31 must
// not wrap to a negative int, nor 2^63 to 0.
int dof_number(const Json& x, const std::string& where) {
  if (!x.is_number_integer()) throw ModelError(where, "expected an integer DOF number");
  const bool fits = x.is_number_unsigned()
                        ? x.get<std::uint64_t>() <= 2147483647u
                        : x.get<std::int64_t>() >= 0 && x.get<std::int64_t>() <= 2147483647;
  if (!fits)
    throw ModelError(where, "DOF number " + x.dump() + " is out of range (0 to 2147483647)");
  return x.get<int>();
}

// "correlation_table": [[…], …]  or  {"rows": [[…], …], "join": "same" | "deepest"}.
CorrelationSpec read_correlation_table(const Json& table, const std::string& where) {
  const Json* tp = &table;
  CorrelationSpec cs;
  cs.where = where;
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
    for (std::size_t k = 0; k < t[r].size(); ++k)
      row.push_back(dof_number(t[r][k], w + "/" + std::to_string(k)));
    cs.rows.push_back(std::move(row));
  }
  return cs;
}

MechanismSpec parse_document(const Catalog& catalog, const Json& root, const std::string& source) {
  MechanismSpec spec;
  spec.where = source + ": ";
  const auto path = [&](const std::string& s) { return source + ": /" + s; };
  for (auto it = root.begin(); it != root.end(); ++it) {
    static const char* known[] = {
        "name",    "description",  "gravity",     "bodies",  "couplings",
        "loads",   "frames",       "constraints", "springs", "correlation_table",
        "$schema", "flexible_bars"};
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
  if (root["bodies"].size() > static_cast<std::size_t>(kMaxBodies))  // before anything is built
    throw ModelError(path("bodies"), too_many_bodies_text(root["bodies"].size()));
  // The file's bodies, then each flexible bar's (io/flexible_bar.hpp), each with its own path.
  Json bodies = root["bodies"];
  std::vector<std::string> where;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    where.push_back(path("bodies/" + std::to_string(i)));
  read_list(root, "flexible_bars", source, [&](const Params& p, std::size_t) {
    FlexibleBarParts bar = flexible_bar_parts(p);
    for (Json& b : bar.bodies) {
      where.push_back(p.where() + " (its body " + quoted_text(b["name"].get<std::string>()) + ")");
      bodies.push_back(std::move(b));
    }
    spec.bars.push_back(std::move(bar.centreline));
    if (bodies.size() > static_cast<std::size_t>(kMaxBodies))
      throw ModelError(p.where(), too_many_bodies_text(bodies.size()));
  });
  const std::map<std::string, Vec3> qualified = qualified_nodes(bodies);
  for (std::size_t i = 0; i < bodies.size(); ++i)
    spec.bodies.push_back(read_body(catalog, bodies[i], where[i], qualified));
  const BodiesByName by_name = bodies_by_name(bodies);
  read_list(root, "couplings", source,
            [&](const Params& p, std::size_t) { spec.couplings.push_back(read_coupling(p)); });
  read_list(root, "loads", source,
            [&](const Params& p, std::size_t) { spec.loads.push_back(read_load(p, by_name)); });
  read_list(root, "frames", source,
            [&](const Params& p, std::size_t) { spec.frames.push_back(read_frame(p, by_name)); });
  read_list(root, "constraints", source, [&](const Params& p, std::size_t i) {
    spec.constraints.push_back(read_constraint(p, by_name, i));
  });
  read_list(root, "springs", source, [&](const Params& p, std::size_t i) {
    spec.springs.push_back(read_spring(p, by_name, i));
  });
  if (root.contains("correlation_table"))
    spec.correlation = read_correlation_table(root["correlation_table"], path("correlation_table"));
  return spec;
}

}  // namespace

FlexibleBarSpec parse_flexible_bar(const Catalog& catalog, const Json& bar,
                                   const std::string& where) {
  FlexibleBarParts parts = flexible_bar_parts(Params(bar, where));
  FlexibleBarSpec out{{}, std::move(parts.centreline)};
  for (const Json& b : parts.bodies)
    out.bodies.push_back(read_body(
        catalog, b, where + " (its body " + quoted_text(b["name"].get<std::string>()) + ")", {}));
  return out;
}

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

}  // namespace femdyn
