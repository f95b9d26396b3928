#include "io/urdf_loader.hpp"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "io/input_file.hpp"
#include "io/urdf_reading.hpp"
#include "io/xml_error.hpp"

namespace femdyn {
namespace {

using namespace urdf_reading;

// The first place in the document that needs xacro, or "": an element of the xacro namespace
// (<xacro:macro>, <xacro:include>, whatever prefix an xmlns binds to xacro's URI), or a
// substitution ${…} or $(…) in an attribute. A declaration alone (xmlns:xacro on <robot>, which
// exported files keep) and xacro inside comments (not elements) need nothing. Iterative, in
// document order: no recursion for a hostile file's depth.
std::string needs_xacro(const XMLElement* robot) {
  std::vector<std::string> prefixes = {"xacro:"};
  std::vector<const XMLElement*> order, stack = {robot};
  while (!stack.empty()) {
    const XMLElement* e = stack.back();
    stack.pop_back();
    order.push_back(e);
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
      if (std::string name = a->Name(); name.rfind("xmlns:", 0) == 0 &&
                                        std::string(a->Value()).find("xacro") != std::string::npos)
        prefixes.push_back(name.substr(6) + ":");
    for (const XMLElement* c = e->LastChildElement(); c; c = c->PreviousSiblingElement())
      stack.push_back(c);
  }
  for (const XMLElement* e : order) {
    const std::string tag = e->Name();
    const std::string at = "<" + echo_text(tag) + "> at line " + std::to_string(e->GetLineNum());
    for (const std::string& p : prefixes)
      if (tag.rfind(p, 0) == 0) return at + " is a xacro element";
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next())
      if (const std::string value = a->Value();
          value.find("${") != std::string::npos || value.find("$(") != std::string::npos)
        return at + " has a xacro substitution, " + echo_text(a->Name()) + "=" + quoted_text(value);
  }
  return {};
}

// The document's <robot>; plain URDF only (a file that needs xacro is refused, naming where).
const XMLElement* robot_element(tinyxml2::XMLDocument& doc, const std::string& text,
                                const std::string& source) {
  if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
    throw ModelError(source, xml_error_text(doc));
  const XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw ModelError(source, "no <robot> element");
  if (const std::string why = needs_xacro(robot); !why.empty())
    throw ModelError(source, why +
                                 ": the file needs xacro, which femdyn does not run; expand it "
                                 "first (xacro robot.urdf.xacro > robot.urdf)");
  return robot;
}

// A <material>'s colour: its own <color rgba>, else that of the robot's material of its name.
std::optional<Eigen::Vector4d> material_color(const Ctx& c, const XMLElement* robot,
                                              const XMLElement* material, const std::string& who) {
  if (!material) return std::nullopt;
  if (const XMLElement* color = material->FirstChildElement("color")) {
    std::istringstream in(color->Attribute("rgba") ? color->Attribute("rgba") : "");
    Eigen::Vector4d rgba;
    for (int i = 0; i < 4; ++i)
      if (!(in >> rgba[i]) || !std::isfinite(rgba[i])) c.fail(who, "<color rgba> needs 4 numbers");
    return rgba;
  }
  const char* name = material->Attribute("name");
  for (const XMLElement* m = robot->FirstChildElement("material"); m && name;
       m = m->NextSiblingElement("material"))
    if (m != material && m->Attribute("name", name)) return material_color(c, robot, m, who);
  return std::nullopt;
}

// A mesh's file: package://NAME/rest in a folder NAME above the URDF (a ROS package's layout)
// or under an entry of ROS_PACKAGE_PATH; file:///path; else relative to the URDF's folder.
void find_mesh(const std::string& urdf_path, Visual& v) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::absolute(fs::path(urdf_path)).parent_path();
  std::vector<fs::path> candidates;
  const std::string package = "package://", file = "file://";
  if (v.mesh.rfind(package, 0) == 0) {
    const std::string rest = v.mesh.substr(package.size());
    const std::string name = rest.substr(0, rest.find('/'));
    const std::string inside =
        rest.find('/') == std::string::npos ? "" : rest.substr(rest.find('/') + 1);
    for (fs::path up = folder; !up.empty(); up = up.parent_path()) {
      if (up.filename() == name) candidates.push_back(up / inside);
      candidates.push_back(up / name / inside);
      if (up == up.parent_path()) break;
    }
    if (const char* ros = std::getenv("ROS_PACKAGE_PATH")) {
      std::istringstream paths(ros);
      for (std::string p; std::getline(paths, p, ':');)
        if (!p.empty()) candidates.push_back(fs::path(p) / name / inside);
    }
  } else if (v.mesh.rfind(file, 0) == 0) {
    candidates.push_back(v.mesh.substr(file.size()));
  } else if (!v.mesh.empty()) {
    candidates.push_back(fs::path(v.mesh).is_absolute() ? fs::path(v.mesh) : folder / v.mesh);
  }
  for (const fs::path& p : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) {
      v.mesh_path = p.lexically_normal().string();
      return;
    }
  }
  v.mesh_issue = "not found" + std::string(v.mesh.rfind(package, 0) == 0
                                               ? " (its package folder is neither above the URDF "
                                                 "nor on ROS_PACKAGE_PATH)"
                                               : "");
}

Visual visual_of(const Ctx& c, const XMLElement* robot, const XMLElement* visual,
                 const std::string& link) {
  const std::string who = "link " + quoted_text(link) + " <visual>";
  const XMLElement* geometry = visual->FirstChildElement("geometry");
  const XMLElement* shape = geometry ? geometry->FirstChildElement() : nullptr;
  if (!shape) c.fail(who, "no <geometry>");
  const Origin o = origin_of(c, visual, who);
  Visual v;
  v.link = link;
  v.shape = shape->Name();
  v.xyz = o.xyz;
  v.R = rpy_to_rotation(o.rpy);
  v.rgba = material_color(c, robot, visual->FirstChildElement("material"), who);
  if (v.shape == "box") {
    v.size = vec_attr(c, shape, "size", Vec3::Zero(), who);
  } else if (v.shape == "cylinder") {
    v.size = {number_attr(c, shape, "radius", 0, who, true),
              number_attr(c, shape, "length", 0, who, true), 0};
  } else if (v.shape == "sphere") {
    v.size = {number_attr(c, shape, "radius", 0, who, true), 0, 0};
  } else if (v.shape == "mesh") {  // a negative scale mirrors it
    v.size = vec_attr(c, shape, "scale", Vec3::Ones(), who);
    if ((v.size.array() == 0).any()) c.fail(who, "a mesh scale of 0");
    v.mesh = shape->Attribute("filename") ? shape->Attribute("filename") : "";
    find_mesh(c.source, v);
  } else {
    c.fail(who, "unknown geometry <" + echo_text(v.shape) + ">");
  }
  if (v.shape != "mesh" && (v.size.array() < 0).any()) c.fail(who, "a negative size");
  return v;
}

}  // namespace

std::vector<Visual> urdf_visuals(const std::string& text, const std::string& source) {
  const Ctx c{source};
  tinyxml2::XMLDocument doc;
  const XMLElement* robot = robot_element(doc, text, source);
  std::vector<Visual> out;
  for (const XMLElement* link = robot->FirstChildElement("link"); link;
       link = link->NextSiblingElement("link")) {
    const char* name = link->Attribute("name");
    for (const XMLElement* v = link->FirstChildElement("visual"); v && name;
         v = v->NextSiblingElement("visual"))
      try {
        out.push_back(visual_of(c, robot, v, name));
      } catch (const Error& e) {  // listed by the page as not drawn; the model still loads
        out.push_back(unread_visual(name, e.what()));
      }
  }
  return out;
}

namespace {

// The largest |xyz| of the joints' and the inertials' <origin>s (unparsable ones skipped: they
// fail where they are read), or 1 m.
double length_scale(const XMLElement* robot) {
  double L = 0;
  const auto take = [&L](const XMLElement* parent) {
    const XMLElement* o = parent ? parent->FirstChildElement("origin") : nullptr;
    std::istringstream in(o && o->Attribute("xyz") ? o->Attribute("xyz") : "");
    Vec3 x;
    if (in >> x[0] >> x[1] >> x[2] && x.allFinite()) L = std::max(L, x.norm());
  };
  for (const XMLElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint"))
    take(j);
  for (const XMLElement* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link"))
    take(l->FirstChildElement("inertial"));
  return L > 0 && L < 1e100 ? L : 1.0;
}

// The <link>s by name, in file order. A joint's parent "world" that no link defines is the world
// itself (Drake's convention): it becomes the root, a link without mass.
struct Links {
  std::map<std::string, const XMLElement*> by_name;
  std::vector<std::string> order;
};

Links read_links(const Ctx& c, const XMLElement* robot) {
  Links links;
  for (const XMLElement* l = robot->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    const char* name = l->Attribute("name");
    if (!name || !*name) c.fail("a <link>", "has no name");
    if (!links.by_name.emplace(name, l).second)
      c.fail(std::string("link '") + name + "'", "is defined twice");
    links.order.push_back(name);
  }
  if (links.by_name.empty()) throw ModelError(c.source, "no <link> elements");
  for (const XMLElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint"))
    if (const XMLElement* p = j->FirstChildElement("parent");
        p && p->Attribute("link", "world") && !links.by_name.count("world")) {
      links.by_name.emplace("world", nullptr);
      links.order.insert(links.order.begin(), "world");
    }
  // Every link but the root becomes a body: refused here when too many, before the joints.
  if (links.by_name.size() - 1 > static_cast<std::size_t>(kMaxBodies))
    throw ModelError(c.source, too_many_bodies_text(links.by_name.size() - 1) +
                                   " (one per <link> but the root)");
  return links;
}

// The <joint>s in file order, checked to make one tree over the links; returns the root link.
std::string read_tree(const Ctx& c, const XMLElement* robot, const Links& links,
                      std::vector<JointInfo>& joints) {
  std::map<std::string, std::string> parent_joint;  // child link -> joint name
  std::set<std::string> joint_names;
  for (const XMLElement* j = robot->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    const char* name = j->Attribute("name");
    if (!name || !*name) c.fail("a <joint>", "has no name");
    const std::string who = std::string("joint '") + name + "'";
    if (!joint_names.insert(name).second) c.fail(who, "is defined twice");
    const XMLElement* p = j->FirstChildElement("parent");
    const XMLElement* ch = j->FirstChildElement("child");
    const char* pl = p ? p->Attribute("link") : nullptr;
    const char* cl = ch ? ch->Attribute("link") : nullptr;
    if (!pl) c.fail(who, "has no <parent link=…>");
    if (!cl) c.fail(who, "has no <child link=…>");
    if (!links.by_name.count(pl)) c.fail(who, "parent link " + quoted_text(pl) + " does not exist");
    if (!links.by_name.count(cl)) c.fail(who, "child link " + quoted_text(cl) + " does not exist");
    if (std::string(pl) == cl) c.fail(who, "connects link '" + std::string(cl) + "' to itself");
    if (std::string(cl) == "world") c.fail(who, "a link named 'world' can only be the root");
    auto [it, fresh] = parent_joint.emplace(cl, name);
    if (!fresh)
      c.fail(who, "link '" + std::string(cl) + "' is already the child of joint '" + it->second +
                      "' (a loop: URDF describes trees)");
    joints.push_back({j, name, pl, cl});
  }
  std::vector<std::string> roots;
  for (const auto& name : links.order)
    if (!parent_joint.count(name)) roots.push_back(name);
  if (roots.size() != 1) {
    std::string list;
    for (const auto& r : roots) list += (list.empty() ? "'" : ", '") + r + "'";
    throw ModelError(c.source, roots.empty() ? "no root link (the joints form a loop)"
                                             : "more than one root link: " + list);
  }
  // Every link must hang from the root: every other link has one parent joint, so a link the
  // walk down from the root does not reach hangs from a loop of joints. One walk, O(links).
  std::map<std::string, std::vector<std::string>> children;  // link -> child links
  for (const JointInfo& ji : joints) children[ji.parent].push_back(ji.child);
  std::set<std::string> reached = {roots[0]};
  for (std::vector<std::string> stack = {roots[0]}; !stack.empty();) {
    const auto below = children.find(stack.back());
    stack.pop_back();
    if (below == children.end()) continue;
    for (const std::string& child : below->second)
      if (reached.insert(child).second) stack.push_back(child);
  }
  for (const auto& name : links.order)
    if (!reached.count(name)) c.fail("link '" + name + "'", "is on a loop of joints");
  return roots[0];
}

// What a joint of one coordinate reads: <limit lower upper effort velocity>, <dynamics damping
// friction>, and <mimic> as a coupling.
void one_coordinate_joint(const Ctx& c, const JointInfo& ji, const std::string& type,
                          const std::set<std::string>& joint_names, Json& joint, Json& couplings,
                          std::vector<std::string>& notes) {
  const std::string who = "joint " + quoted_text(ji.name);
  const Vec3 axis = vec_attr(c, ji.e->FirstChildElement("axis"), "xyz", Vec3::UnitX(), who);
  if (!(axis.norm() > 1e-12)) c.fail(who, "axis is zero");
  joint["axis"] = vec3_json(axis.normalized());
  const XMLElement* lim = ji.e->FirstChildElement("limit");
  if (type != "continuous" && lim && (lim->Attribute("lower") || lim->Attribute("upper"))) {
    const double lo = number_attr(c, lim, "lower", 0, who),
                 hi = number_attr(c, lim, "upper", 0, who);
    if (lo > hi) c.fail(who, "limit lower > upper");
    if (lo < hi) joint["limits"] = {lo, hi};
  }
  // <limit effort velocity>: τ saturated at ±effort, |θ̇| beyond velocity reported. URDF
  // requires both; 0 (common for "not given") leaves that limit out, with a warning.
  for (const auto& [attr, key] :
       {std::pair{"effort", "effort_limit"}, std::pair{"velocity", "velocity_limit"}}) {
    if (!lim || !lim->Attribute(attr)) continue;
    const double x = number_attr(c, lim, attr, 0, who);
    if (x < 0) c.fail(who, std::string("negative limit ") + attr);
    if (x > 0)
      joint[key] = x;
    else
      notes.push_back(c.source + ": " + who + ": <limit " + attr + "=\"0\"> read as no " + attr +
                      " limit");
  }
  if (const XMLElement* dyn = ji.e->FirstChildElement("dynamics")) {
    const double damping = number_attr(c, dyn, "damping", 0, who);
    const double friction = number_attr(c, dyn, "friction", 0, who);
    if (damping < 0) c.fail(who, "negative damping");
    if (damping > 0) joint["damping"] = damping;
    if (friction < 0) c.fail(who, "negative friction");
    if (friction > 0) joint["friction"] = friction;  // Coulomb, regularised (docs/control.md)
  }
  if (const XMLElement* mimic = ji.e->FirstChildElement("mimic")) {
    const char* leader = mimic->Attribute("joint");
    if (!leader) c.fail(who, "<mimic> has no joint");
    if (!joint_names.count(leader)) c.fail(who, "mimics unknown joint " + quoted_text(leader));
    couplings.push_back({{"joint", ji.name},
                         {"follows", leader},
                         {"ratio", number_attr(c, mimic, "multiplier", 1.0, who)},
                         {"offset", number_attr(c, mimic, "offset", 0.0, who)}});
  }
}

// A <joint> as femdyn's joint: revolute, continuous (a revolute), prismatic, fixed, planar,
// floating (free) and PyBullet's spherical. What a type does not use is reported.
Json joint_json(const Ctx& c, const JointInfo& ji, const std::set<std::string>& joint_names,
                Json& couplings, std::vector<std::string>& notes) {
  const std::string who = "joint " + quoted_text(ji.name);
  const char* type_c = ji.e->Attribute("type");
  const std::string type = type_c ? type_c : "";
  static const std::map<std::string, std::string> femdyn_type = {
      {"revolute", "revolute"},  {"continuous", "revolute"}, {"prismatic", "prismatic"},
      {"fixed", "fixed"},        {"floating", "free"},       {"planar", "planar"},
      {"spherical", "spherical"}};
  const auto known = femdyn_type.find(type);
  if (known == femdyn_type.end()) c.fail(who, "unknown type " + quoted_text(type));
  const Origin o = origin_of(c, ji.e, who);
  Json joint = {{"name", ji.name},
                {"type", known->second},
                {"origin", {{"xyz", vec3_json(o.xyz)}, {"rpy", vec3_json(o.rpy)}}}};
  const auto ignored = [&](const char* element, const std::string& why) {
    if (ji.e->FirstChildElement(element))
      notes.push_back(c.source + ": " + who + ": <" + element + "> ignored on a " + type +
                      " joint (" + why + ")");
  };
  if (type == "revolute" || type == "continuous" || type == "prismatic") {
    one_coordinate_joint(c, ji, type, joint_names, joint, couplings, notes);
    return joint;
  }
  const std::string why = type == "fixed" ? "it has no coordinate"
                                          : "femdyn models none on a joint of several coordinates";
  for (const char* unused : {"limit", "dynamics", "mimic"}) ignored(unused, why);
  if (type == "planar") {  // the axis is the plane's normal
    const Vec3 axis = vec_attr(c, ji.e->FirstChildElement("axis"), "xyz", Vec3::UnitZ(), who);
    if (!(axis.norm() > 1e-12)) c.fail(who, "axis is zero");
    joint["axis"] = vec3_json(axis.normalized());
  } else if (type != "fixed") {
    ignored("axis", "it turns about every axis");
  }
  return joint;
}

}  // namespace

UrdfResult urdf_to_model(const std::string& text, const std::string& source,
                         const UrdfOptions& options) {
  tinyxml2::XMLDocument doc;
  const XMLElement* robot = robot_element(doc, text, source);
  const Ctx c{source, length_scale(robot)};
  const Links links = read_links(c, robot);
  std::vector<JointInfo> joints;
  const std::string root = read_tree(c, robot, links, joints);
  if (!options.floating_base && std::all_of(joints.begin(), joints.end(), [](const JointInfo& ji) {
        return ji.e->Attribute("type", "fixed");
      }))
    throw ModelError(source, "root link " + quoted_text(root) +
                                 " is welded to the world and no joint moves: nothing to "
                                 "compute (a free-flying robot: --floating-base, or "
                                 "\"root_joint\": \"free\" in a reference)");
  UrdfResult out;
  const std::map<std::string, Json> element =
      link_elements(c, links.by_name, links.order, joints, root, options, out.warnings);
  std::set<std::string> joint_names;
  for (const JointInfo& ji : joints) joint_names.insert(ji.name);
  Json bodies = Json::array(), couplings = Json::array();
  for (const JointInfo& ji : joints) {
    const bool under_world = ji.parent == root && !options.floating_base;
    Json body = {{"name", ji.child},
                 {"parent", under_world ? "world" : ji.parent},
                 {"joint", joint_json(c, ji, joint_names, couplings, out.warnings)}};
    if (const Json& e = element.at(ji.child); !e.is_null()) body["elements"] = Json::array({e});
    bodies.push_back(body);
  }
  // The root link: welded to the world (its inertia never moves), or floating.
  if (options.floating_base) {
    if (root == "world")
      c.fail("link 'world'",
             "the root link is the world itself, to which the robot is joined: "
             "--floating-base floats a root link that is a part of the robot");
    Json base = {
        {"name", root}, {"parent", "world"}, {"joint", {{"name", root}, {"type", "free"}}}};
    if (const Json& e = element.at(root); !e.is_null()) base["elements"] = Json::array({e});
    bodies.insert(bodies.begin(), base);
  }
  const char* name = robot->Attribute("name");
  out.model = {{"name", name ? name : root},
               {"description", "imported from " + source + "; root link '" + root + "' " +
                                   (options.floating_base ? "floating (a free joint to the world)"
                                                          : "welded to the world")},
               {"gravity", {0, 0, -9.81}},
               {"bodies", bodies}};
  if (!couplings.empty()) out.model["couplings"] = couplings;
  return out;
}

UrdfResult read_urdf(const std::string& path, const UrdfOptions& options) {
  return urdf_to_model(read_input_file(path), path, options);
}

}  // namespace femdyn
