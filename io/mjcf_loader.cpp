#include "io/mjcf_loader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numbers>
#include <set>

#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "io/mjcf_reading.hpp"

namespace femdyn {
namespace {

using namespace mjcf;

// Where the walk is: a MuJoCo body (or <frame>) to read, the femdyn body it hangs from, its
// parent's frame in that femdyn body's frame, and the childclass in force.
struct Visit {
  const XMLElement* e;
  std::string parent;
  Pose in_parent;  // the MuJoCo parent frame in the femdyn parent body's frame
  Pose world0;     // the MuJoCo parent frame in the world, as written
  std::string childclass;
  const XMLElement* body = nullptr;  // the MuJoCo body a <frame> is in (null: the world)
};

// A <frame>'s own joints and geoms: a joint is refused; a geom too where its body's mass comes
// from geoms (femdyn reads a body's own geoms); otherwise counted as unused (contacts).
void check_frame(const Document& doc, const XMLElement& frame, const XMLElement* body) {
  const Compiler& c = doc.compiler();
  const bool mass_from_geoms = body && (c.inertia_from_geom == Compiler::FromGeom::always ||
                                        (c.inertia_from_geom == Compiler::FromGeom::automatic &&
                                         doc.children(*body, "inertial").empty()));
  for (const XMLElement* e : doc.children(frame)) {
    const std::string tag = e->Name();
    if (tag == "joint" || tag == "freejoint" || (tag == "geom" && mass_from_geoms))
      doc.fail(*e, "a " + tag + " inside a <frame> is not read yet (femdyn reads a body's own)");
  }
}

struct Walk {
  const Document& doc;
  const MjcfOptions& options;
  Json bodies = Json::array();
  Tree tree;
  std::set<std::string> body_names, joint_names;
  std::vector<std::string> notes;
  MjcfMassNotes mass_notes;
  std::vector<Visual> visuals;
  Json sites = Json::array();  // named sites, as frames on their femdyn bodies
  struct Massed {
    const XMLElement* body;  // the MuJoCo body
    std::size_t index;       // its femdyn body, in `bodies`
    Vec3 shift;
    CentroidalMass mass;
  };
  std::vector<Massed> masses;         // per MuJoCo body (settotalmass scales them all)
  int mj_body = 0, mj_joint = 0;      // MuJoCo's indices (world is body 0)
  std::map<std::string, int> unused;  // what femdyn does not model, counted
};

std::string fresh(std::set<std::string>& names, std::string name) {
  while (!names.insert(name).second) name += "_";
  return name;
}

Json quat_json(const Mat3& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;
  return Json::array({q.w(), q.x(), q.y(), q.z()});
}

Json origin_json(const Pose& X) { return {{"xyz", vec3_json(X.p)}, {"quat", quat_json(X.R)}}; }

// A hinge or slide joint's one-coordinate keys: axis, limits, spring, damping, armature,
// friction, and its `ref` folded into the origin (so that q is MuJoCo's qpos).
void one_coordinate(Walk& w, const XMLElement& j, const std::string& cls, bool hinge,
                    const Vec3& axis, Pose& origin, Json& joint) {
  const Document& doc = w.doc;
  const double unit = hinge && doc.compiler().degrees ? std::numbers::pi / 180 : 1.0;
  const double ref = doc.number(j, "ref", cls, 0) * unit;
  if (hinge)
    origin.R = origin.R * Eigen::AngleAxisd(-ref, axis).toRotationMatrix();
  else
    origin.p -= origin.R * axis * ref;
  joint["axis"] = vec3_json(axis);
  if (ref != 0) joint["initial"] = ref;
  const char* limited = doc.attr(j, "limited", cls);
  const std::vector<double> range = doc.numbers(j, "range", cls, 2);
  const bool limits =
      limited ? std::strcmp(limited, "true") == 0 || (std::strcmp(limited, "auto") == 0 &&
                                                      doc.compiler().autolimits && !range.empty())
              : doc.compiler().autolimits && !range.empty();
  if (limits && !range.empty()) {
    if (range[0] > range[1]) doc.fail(j, "range: lower > upper");
    if (range[0] < range[1]) joint["limits"] = {range[0] * unit, range[1] * unit};
  }
  const auto non_negative = [&](const char* name) {
    const double x = doc.number(j, name, cls, 0);
    if (x < 0) doc.fail(j, std::string(name) + " is negative");
    return x;
  };
  if (const double k = non_negative("stiffness"); k > 0)
    joint["spring"] = {{"stiffness", k}, {"rest", doc.number(j, "springref", cls, 0) * unit}};
  if (const double c = non_negative("damping"); c > 0) joint["damping"] = c;
  if (const double a = non_negative("armature"); a > 0) joint["armature"] = a;
  if (const double f = non_negative("frictionloss"); f > 0) {
    joint["friction"] = f;
    ++w.unused["frictionloss read as regularised Coulomb friction (MuJoCo: a constraint)"];
  }
}

// A ball or free joint: its armature is its rotor (I_a on each rate, as MuJoCo's dof_armature;
// core/joints/rotor.hpp), its damping a damper on each rate (core/joints/passive.hpp); a spring
// or friction loss reported as left out of τ and q̈.
void many_coordinates(Walk& w, const XMLElement& j, const std::string& cls, bool ball,
                      Json& joint) {
  const Document& doc = w.doc;
  if (const double a = doc.number(j, "armature", cls, 0); a != 0) {
    if (a < 0) doc.fail(j, "armature is negative");
    joint["armature"] = a;
  }
  if (const double c = doc.number(j, "damping", cls, 0); c != 0) {
    if (c < 0) doc.fail(j, "damping is negative");
    joint["damping"] = c;
  }
  for (const char* name : {"stiffness", "frictionloss"})
    if (doc.number(j, name, cls, 0) != 0)
      ++w.unused[std::string(name) + " on a ball or free joint"];
  if (const std::vector<double> range = doc.numbers(j, "range", cls, 2);
      ball && !range.empty() && range[1] > 0)
    ++w.unused["a ball joint's cone limit"];
}

// The femdyn joint of one MuJoCo joint; `origin` is its frame in the femdyn parent's frame.
Json joint_json(Walk& w, const XMLElement& j, const std::string& cls, const std::string& type,
                Pose origin, const std::string& name) {
  const Document& doc = w.doc;
  Json joint = {{"name", name}};
  if (type == "hinge" || type == "slide") {
    const Vec3 a = doc.vec3(j, "axis", cls, Vec3::UnitZ());
    if (!(a.norm() > 1e-14)) doc.fail(j, "axis is zero");
    joint["type"] = type == "hinge" ? "revolute" : "prismatic";
    one_coordinate(w, j, cls, type == "hinge", a.normalized(), origin, joint);
  } else if (type == "ball" || type == "free") {
    joint["type"] = type == "ball" ? "spherical" : "free";
    many_coordinates(w, j, cls, type == "ball", joint);
  } else {
    doc.fail(j, "type " + quoted_text(type) + ": expected hinge, slide, ball or free");
  }
  joint["origin"] = origin_json(origin);
  return joint;
}

// Where a MuJoCo body's children hang: its femdyn body, the MuJoCo body's frame in that body's
// frame, and in the world as written.
struct Placed {
  std::string femdyn;
  Pose below, world0;
};

// A body's named sites, as frames on the femdyn body that carries it (an unnamed one is
// counted as not used).
void read_sites(Walk& w, const XMLElement& body, const std::string& childclass,
                const Placed& placed) {
  for (const XMLElement* site : w.doc.children(body, "site")) {
    const char* name = site->Attribute("name");
    if (!name) {
      ++w.unused["unnamed sites"];
      continue;
    }
    const Pose F = placed.below * pose_of(w.doc, *site, w.doc.class_of(*site, childclass));
    w.sites.push_back({{"name", name},
                       {"body", placed.femdyn},
                       {"xyz", vec3_json(F.p)},
                       {"rpy", vec3_json(rotation_rpy(F.R))}});
  }
}

// A MuJoCo body: its chain of femdyn bodies (one per joint, or one welded), its mass on the last.
Placed read_body(Walk& w, const Visit& v, const std::string& childclass) {
  const Document& doc = w.doc;
  const XMLElement& body = *v.e;
  const int index = ++w.mj_body;
  const char* own = body.Attribute("name");
  const std::string name = own ? own : "body" + std::to_string(index);
  if (w.tree.bodies.count(name)) doc.fail(body, "a second body of this name");
  const Pose B = v.in_parent * pose_of(doc, body, "");  // the body frame, femdyn parent's frame
  if (doc.number(body, "gravcomp", "", 0) != 0) ++w.unused["bodies' gravity compensation"];
  std::vector<std::pair<const XMLElement*, std::string>> joints;  // element, type
  for (const XMLElement* c : doc.children(body)) {
    if (!std::strcmp(c->Name(), "freejoint")) joints.push_back({c, "free"});
    if (!std::strcmp(c->Name(), "joint")) {
      const char* t = doc.attr(*c, "type", doc.class_of(*c, childclass));
      joints.push_back({c, t ? t : "hinge"});
    }
  }
  std::string parent = v.parent;
  Vec3 at = Vec3::Zero();  // the previous joint's pos, in the body frame
  Json last;
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const auto& [j, type] = joints[k];
    const std::string cls = std::strcmp(j->Name(), "freejoint") ? doc.class_of(*j, childclass) : "";
    const char* jname = j->Attribute("name");
    const std::string joint_name =
        fresh(w.joint_names, jname ? jname : "joint" + std::to_string(w.mj_joint));
    ++w.mj_joint;
    if (type == "free" && (v.parent != "world" || joints.size() > 1))
      doc.fail(*j, "a free joint must be the only joint of a body at the top of the tree");
    const Vec3 pos = type == "free" ? Vec3::Zero() : doc.vec3(*j, "pos", cls, Vec3::Zero());
    // The first joint's frame is B·T(pos); the next sits at its pos from the previous one's.
    const Pose origin = type == "free" ? Pose{}
                                       : (k == 0 ? B * Pose{pos, Mat3::Identity()}
                                                 : Pose{pos - at, Mat3::Identity()});
    at = pos;
    const bool carrier = k + 1 == joints.size();
    const std::string femdyn_name =
        carrier ? fresh(w.body_names, name) : fresh(w.body_names, name + "." + joint_name);
    w.bodies.push_back({{"name", femdyn_name},
                        {"parent", parent},
                        {"joint", joint_json(w, *j, cls, type, origin, joint_name)}});
    if (jname) {
      const bool hinge = type == "hinge" && doc.compiler().degrees;
      const double ref = type == "hinge" || type == "slide" ? doc.number(*j, "ref", cls, 0) : 0;
      w.tree.joints[jname] = {joint_name, type, hinge ? ref * std::numbers::pi / 180 : ref};
    }
    parent = femdyn_name;
  }
  if (joints.empty())
    w.bodies.push_back(
        {{"name", fresh(w.body_names, name)},
         {"parent", parent},
         {"joint",
          {{"name", fresh(w.joint_names, name)}, {"type", "fixed"}, {"origin", origin_json(B)}}}});
  const Placed placed{w.bodies.back()["name"], Pose{-at, Mat3::Identity()},
                      v.world0 * pose_of(doc, body, "")};
  w.tree.bodies[name] = {placed.femdyn, at, placed.world0};
  w.masses.push_back(
      {&body, w.bodies.size() - 1, at, body_mass(doc, body, childclass, w.mass_notes)});
  add_visuals(doc, body, childclass, placed.femdyn, placed.below, w.visuals);
  read_sites(w, body, childclass, placed);
  return placed;
}

// What a body (or the world, or a <frame>) holds that femdyn does not model, counted for the
// one-line report; a body's sites are frames (read_sites).
void count_unused(Walk& w, const XMLElement& e, bool body) {
  for (const XMLElement* c : w.doc.children(e)) {
    const std::string tag = c->Name();
    if (tag == "geom")
      ++w.unused["geoms' contacts"];
    else if (tag == "site" && !body)
      ++w.unused["sites outside bodies"];
    else if (tag == "camera" || tag == "light")
      ++w.unused["cameras and lights"];
    else if (tag == "composite" || tag == "flexcomp" || tag == "replicate" || tag == "attach")
      w.doc.fail(*c, "<" + tag + "> is not read by femdyn (expand the model in MuJoCo first)");
  }
}

// The body tree, depth first in file order (MuJoCo's body order), without recursion.
void walk_tree(Walk& w) {
  std::vector<Visit> stack;
  const auto push_children = [&](const XMLElement& e, const std::string& parent, const Pose& in,
                                 const Pose& world0, const std::string& cls,
                                 const XMLElement* body) {
    const std::vector<const XMLElement*> kids = w.doc.children(e);
    for (auto it = kids.rbegin(); it != kids.rend(); ++it)
      if (!std::strcmp((*it)->Name(), "body") || !std::strcmp((*it)->Name(), "frame"))
        stack.push_back({*it, parent, in, world0, cls, body});
  };
  for (const XMLElement* world : w.doc.sections("worldbody")) {
    count_unused(w, *world, false);
    add_visuals(w.doc, *world, "", "world", Pose{}, w.visuals);
    push_children(*world, "world", Pose{}, Pose{}, "", nullptr);
    while (!stack.empty()) {
      const Visit v = stack.back();
      stack.pop_back();
      const std::string childclass = w.doc.childclass_of(*v.e, v.childclass);
      if (!std::strcmp(v.e->Name(), "frame")) {
        const Pose F = pose_of(w.doc, *v.e, "");
        check_frame(w.doc, *v.e, v.body);
        count_unused(w, *v.e, false);
        push_children(*v.e, v.parent, v.in_parent * F, v.world0 * F, childclass, v.body);
        continue;
      }
      if (w.mj_body >= kMaxBodies)
        throw ModelError(w.doc.path(), too_many_bodies_text(w.mj_body + 1));
      const Placed placed = read_body(w, v, childclass);
      count_unused(w, *v.e, true);
      push_children(*v.e, placed.femdyn, placed.below, placed.world0, childclass, v.e);
    }
  }
}

// <compiler settotalmass>: every body's mass and inertia scaled to make the total.
void set_total_mass(Walk& w) {
  const double target = w.doc.compiler().settotalmass;
  if (!(target > 0)) return;
  double total = 0;
  for (const Walk::Massed& m : w.masses) total += m.mass.mass;
  if (!(total > 0)) throw ModelError(w.doc.path(), "settotalmass on a model without mass");
  for (Walk::Massed& m : w.masses) {
    m.mass.mass *= target / total;
    m.mass.inertia *= target / total;
  }
}

// <option gravity>; fluid forces (density, viscosity, wind) are counted as not modelled.
Vec3 gravity(Walk& w) {
  Vec3 g(0, 0, -9.81);
  for (const XMLElement* option : w.doc.sections("option")) {
    g = w.doc.vec3(*option, "gravity", "", g);
    if (w.doc.number(*option, "density", "", 0) != 0 ||
        w.doc.number(*option, "viscosity", "", 0) != 0 ||
        w.doc.vec3(*option, "wind", "", Vec3::Zero()) != Vec3::Zero())
      ++w.unused["<option> with fluid forces (density, viscosity, wind)"];
  }
  return g;
}

// What the model holds that femdyn does not model, in one line.
std::string unused_text(Walk& w) {
  const Document& doc = w.doc;
  for (const char* section : {"actuator", "sensor", "tendon", "contact", "keyframe"})
    for (const XMLElement* s : doc.sections(section))
      w.unused[std::string(section) + (std::strcmp(section, "keyframe") ? " elements" : "s")] +=
          static_cast<int>(doc.children(*s).size());
  std::string list;
  for (const auto& [what, count] : w.unused)
    if (count > 0) list += (list.empty() ? "" : ", ") + std::to_string(count) + " " + what;
  return list.empty() ? "" : doc.path() + ": not modelled by femdyn (listed, not used): " + list;
}

// The sites as the model's frames; one named like a body or an earlier site is counted as not
// used (a frame's name is unique among bodies and frames).
void add_sites(Walk& w, Json& model) {
  std::set<std::string> names;
  for (const Json& b : w.bodies) names.insert(b["name"].get<std::string>());
  Json frames = Json::array();
  for (Json& site : w.sites) {
    if (!names.insert(site["name"].get<std::string>()).second) {
      ++w.unused["sites named like a body or another site"];
      continue;
    }
    frames.push_back(std::move(site));
  }
  if (!frames.empty()) model["frames"] = std::move(frames);
}

}  // namespace

MjcfResult read_mjcf(const std::string& path, const MjcfOptions& options) {
  Document doc(path);
  if (options.exact_mesh_inertia) doc.make_every_mesh_exact();
  Walk w{doc, options};
  w.tree.bodies["world"] = {"world", Vec3::Zero(), Pose{}};
  walk_tree(w);
  if (w.bodies.empty()) throw ModelError(path, "<worldbody> holds no body: nothing to compute");
  set_total_mass(w);
  for (const Walk::Massed& m : w.masses)
    if (Json e = mass_element(doc, *m.body, m.mass, m.shift, options, w.notes); !e.is_null())
      w.bodies[m.index]["elements"] = Json::array({e});
  const char* name = doc.root().Attribute("model");
  MjcfResult out;
  out.model = {{"name", name ? name : std::filesystem::path(path).stem().string()},
               {"description", "imported from " + path + " (MJCF)"},
               {"gravity", vec3_json(gravity(w))},
               {"bodies", w.bodies}};
  add_sites(w, out.model);
  read_equalities(doc, w.tree, out.model, w.notes);
  if (!w.mass_notes.not_solid.empty()) {  // each mesh once, in file order
    std::vector<std::string> names;
    for (const std::string& m : w.mass_notes.not_solid)
      if (std::find(names.begin(), names.end(), m) == names.end()) names.push_back(m);
    std::string list;
    for (const std::string& m : names) list += (list.empty() ? "" : ", ") + m;
    w.notes.push_back(path + ": " + std::to_string(names.size()) +
                      (names.size() == 1 ? " mesh is" : " meshes are") +
                      " not convex, and MuJoCo's default (legacy) inertia, which femdyn "
                      "follows, counts their folds twice (legacy volume / solid's): " +
                      list +
                      "; inertia=\"exact\" on a mesh, or <compiler "
                      "exactmeshinertia=\"true\">, weighs the solid");
  }
  out.warnings = std::move(w.notes);
  out.mass_notes = std::move(w.mass_notes);
  out.visuals = std::move(w.visuals);
  if (const std::string unused = unused_text(w); !unused.empty()) out.warnings.push_back(unused);
  return out;
}

}  // namespace femdyn
