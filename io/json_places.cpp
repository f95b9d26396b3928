#include "io/json_places.hpp"

#include "io/json_text.hpp"

namespace femdyn {
namespace {

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

}  // namespace

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

BodiesByName bodies_by_name(const Json& bodies) {
  BodiesByName by_name;
  for (const Json& b : bodies)
    if (b.is_object() && b.contains("name") && b["name"].is_string())
      by_name[b["name"].get<std::string>()].push_back(&b);
  return by_name;
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

}  // namespace femdyn
