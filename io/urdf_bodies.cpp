// The links' mass as rigid bodies (urdf_reading.hpp: link_elements).
#include <algorithm>
#include <optional>

#include "core/model/names.hpp"
#include "core/spatial/inertia.hpp"
#include "io/centroidal_mass.hpp"
#include "io/urdf_reading.hpp"

namespace femdyn::urdf_reading {
namespace {

// <inertial> -> the link's mass properties in the link frame (the inertia rotated out of the
// <inertial> origin frame), unchecked: a link is checked as part of its rigid body.
CentroidalMass link_mass(const Ctx& c, const XMLElement* link, const std::string& who) {
  const XMLElement* in = link ? link->FirstChildElement("inertial") : nullptr;
  if (!in) return {};
  const XMLElement* mass = in->FirstChildElement("mass");
  if (!mass) c.fail(who, "<inertial> has no <mass>");
  const double m = number_attr(c, mass, "value", 0, who, true);
  if (m < 0) c.fail(who, "negative mass " + format_number(m));
  const XMLElement* ie = in->FirstChildElement("inertia");
  if (!ie) c.fail(who, "<inertial> has no <inertia>");
  const double ixx = number_attr(c, ie, "ixx", 0, who), iyy = number_attr(c, ie, "iyy", 0, who),
               izz = number_attr(c, ie, "izz", 0, who), ixy = number_attr(c, ie, "ixy", 0, who),
               ixz = number_attr(c, ie, "ixz", 0, who), iyz = number_attr(c, ie, "iyz", 0, who);
  Mat3 I;
  I << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
  const Origin o = origin_of(c, in, who);
  const Mat3 R = rpy_to_rotation(o.rpy);  // the <inertial> frame's axes in the link frame
  return {m, o.xyz, R * I * R.transpose()};
}

// What is not physical about a body's inertia, judged against m L² (round-off of a point mass
// is not a negative moment), or nothing.
std::optional<std::string> mass_problem(const Ctx& c, const CentroidalMass& mp) {
  return inertia_problem(mp.inertia, mp.mass * c.length * c.length);
}

// A physical body's element (rigid_body, or rotary_node when massless with an inertia), or
// null when it has neither mass nor inertia.
Json mass_element(const CentroidalMass& mp) {
  if (mp.empty()) return nullptr;
  // Not physical by round-off only (within 1e-9 m L², as checked): the nearest physical tensor.
  const Mat3 I = nearest_physical_inertia(mp.inertia);
  Json rows = Json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(vec3_json(I.row(r).transpose()));
  // Zero mass with an inertia (some exporters' placeholder links, or a pure rotor): a rotary
  // inertia alone.
  if (mp.mass == 0)
    return {{"type", "rotary_node"}, {"node", vec3_json(mp.com)}, {"inertia", rows}};
  return {{"type", "rigid_body"}, {"mass", mp.mass}, {"com", vec3_json(mp.com)}, {"inertia", rows}};
}

// Where each link sits in its rigid body: the body's head (the link on its movable joint, or
// the root) and the link frame's pose in the head's frame, composed along fixed joints.
struct WeldedPose {
  std::string head;
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
};

std::map<std::string, WeldedPose> welded_poses(const Ctx& c, const std::vector<JointInfo>& joints,
                                               const std::string& root) {
  std::map<std::string, std::vector<const JointInfo*>> below;
  for (const JointInfo& ji : joints) below[ji.parent].push_back(&ji);
  std::map<std::string, WeldedPose> pose = {{root, {root}}};
  for (std::vector<std::string> stack = {root}; !stack.empty();) {
    const std::string link = stack.back();
    stack.pop_back();
    const WeldedPose& up = pose.at(link);
    for (const JointInfo* ji : below[link]) {
      WeldedPose& mine = pose[ji->child];
      mine.head = ji->child;
      if (const char* t = ji->e->Attribute("type"); t && std::string(t) == "fixed") {
        const Origin o = origin_of(c, ji->e, "joint " + quoted_text(ji->name));
        mine = {up.head, up.R * rpy_to_rotation(o.rpy), up.R * o.xyz + up.p};
      }
      stack.push_back(ji->child);
    }
  }
  return pose;
}

std::string link_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + quoted_text(n);
  return out;
}

}  // namespace

// Each link's element. The links welded together by fixed joints are one rigid body, and it is
// the body that must be physical (as Pinocchio merges fixed joints): a link whose own tensor is
// not (a sensor, a 1e-6 kg dummy root) has the body's merged mass properties put on the head
// and none of its own, with a note. A body still not physical is refused naming its head, or
// with balance_inertia takes the nearest physical inertia, reported. The links welded to a
// fixed base never move: theirs are not checked (a non-physical one is dropped, noted).
std::map<std::string, Json> link_elements(const Ctx& c,
                                          const std::map<std::string, const XMLElement*>& links,
                                          const std::vector<std::string>& link_order,
                                          const std::vector<JointInfo>& joints,
                                          const std::string& root, const UrdfOptions& options,
                                          std::vector<std::string>& notes) {
  const std::map<std::string, WeldedPose> pose = welded_poses(c, joints, root);
  std::map<std::string, CentroidalMass> own;
  std::map<std::string, std::vector<std::string>> bodies;  // head -> its links, in file order
  for (const std::string& name : link_order) {
    own[name] = link_mass(c, links.at(name), "link " + quoted_text(name));
    bodies[pose.at(name).head].push_back(name);
  }
  const auto note = [&](const std::string& text) { notes.push_back(c.source + ": " + text); };
  std::map<std::string, Json> element;
  for (const auto& [head, members] : bodies) {
    std::vector<std::string> bad;
    for (const std::string& name : members)
      if (const auto problem = mass_problem(c, own[name])) bad.push_back(name);
    const bool never_moves = head == root && !options.floating_base;
    if (bad.empty() || never_moves) {
      for (const std::string& name : members)
        element[name] = std::find(bad.begin(), bad.end(), name) == bad.end()
                            ? mass_element(own[name])
                            : Json(nullptr);
      if (!bad.empty())
        note("link " + link_list(bad) + ": inertia not physical, ignored: welded to the fixed " +
             "base, it never moves");
      continue;
    }
    CentroidalMass body;
    for (const std::string& name : members)
      body = welded(body, own[name].expressed_in(pose.at(name).R, pose.at(name).p));
    std::string who = "link " + quoted_text(head);
    if (members.size() > 1) {
      std::vector<std::string> welded_to_head;
      for (const std::string& name : members)
        if (name != head) welded_to_head.push_back(name);
      who += " (a rigid body with the links welded to it: " + link_list(welded_to_head) + ")";
      note("link " + link_list(bad) + ": " + *mass_problem(c, own[bad[0]]) +
           "; checked as part of the rigid body of link " + quoted_text(head) +
           " (fixed joints), whose merged mass properties it carries");
    }
    if (const auto problem = mass_problem(c, body)) {
      if (!options.balance_inertia)
        c.fail(who, *problem +
                        "; the balance_inertia option (--balance-inertia) takes the "
                        "nearest physical inertia instead");
      const Mat3 balanced = nearest_physical_inertia(body.inertia);
      note(who + ": inertia balanced to the nearest physical one, principal moments " +
           principal_moments_text(body.inertia) + " -> " + principal_moments_text(balanced));
      body.inertia = balanced;
    }
    for (const std::string& name : members) element[name] = nullptr;
    element[head] = mass_element(body);
  }
  return element;
}

}  // namespace femdyn::urdf_reading
