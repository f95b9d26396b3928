#include "io/model_loader.hpp"

#include <cctype>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "compile/compile.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "io/catalog.hpp"
#include "io/coupling_json.hpp"
#include "io/input_file.hpp"
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

}  // namespace

Json model_document(const std::string& path, const LoadOptions& options) {
  if (is_robot_file(path)) return robot_document(path, options);
  const Json root = parse_json(read_text(path), path);
  if (auto ref = robot_reference(path, root, options)) return std::move(ref->first);
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
    if (auto ref = robot_reference(path, root, options)) {
      try {
        return parse_model_json(ref->first, ref->second, catalog);
      } catch (const ModelError& e) {
        rethrow_for_robot_file(e, ref->first, ref->second);
      }
    }
    refuse_balance_on_json(path, options);
    return parse_model_json(root, path, catalog);
  }
  const Json doc = model_document(path, options);
  try {
    return parse_model_json(doc, path, catalog);
  } catch (const ModelError& e) {
    rethrow_for_robot_file(e, doc, path);
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
    rethrow_for_robot_file(e, model_document(path, options), path);
  }
}

}  // namespace femdyn
