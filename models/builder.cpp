#include "models/builder.hpp"

#include <cstdio>

#include "compile/compile.hpp"
#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "core/spatial/inertia.hpp"
#include "elements/lumped_point.hpp"
#include "elements/rigid_body.hpp"
#include "elements/rod.hpp"
#include "elements/rotary_node.hpp"
#include "elements/space_bar.hpp"
#include "models/model_files.hpp"

namespace femdyn {

namespace {

void check_positive(double x, const std::string& where) {
  check_magnitude(x, where, "the number");
  if (!(x > 0)) throw ModelError(where, "must be positive, got " + format_number(x));
}

void check_inertia(const Mat3& I, const std::string& where) {
  for (int k = 0; k < 9; ++k) check_magnitude(I.data()[k], where, "inertia entry");
  if (const auto problem = inertia_problem(I)) throw ModelError(where, *problem);
}

// A fixed joint has no motion, so an axis, limits, a spring or a damper on it would be ignored:
// refused, as the JSON loader refuses those keys on a fixed joint. JointSpec's type defaults to
// fixed, so this is also what catches a moving joint whose type was forgotten (the body would
// be welded to its parent without a word). The axis counts as given when it is not the default.
void check_fixed_joint(const JointSpec& j) {
  if (j.type != JointType::Fixed) return;
  const JointSpec defaults;
  const char* given = j.axis != defaults.axis                                        ? "axis"
                      : j.lower != defaults.lower || j.upper != defaults.upper       ? "limits"
                      : j.stiffness != defaults.stiffness || j.rest != defaults.rest ? "spring"
                      : j.damping != defaults.damping                                ? "damping"
                      : j.armature != defaults.armature || j.gear != defaults.gear   ? "armature"
                      : j.friction != defaults.friction                              ? "friction"
                      : j.effort_limit != defaults.effort_limit     ? "effort_limit"
                      : j.velocity_limit != defaults.velocity_limit ? "velocity_limit"
                      : j.stop                                      ? "stop"
                                                                    : nullptr;
  if (given)
    throw ModelError(j.where + "/" + given,
                     "a fixed joint has no motion: no axis, limits, spring or damping (is the "
                     "joint's type missing? JointSpec's type defaults to fixed)");
}

}  // namespace

MechanismBuilder::MechanismBuilder(std::string name) {
  check_name(name, "builder", "model name");
  spec_.name = std::move(name);
  spec_.where = spec_.name + " (builder): ";
}

void MechanismBuilder::gravity(const Vec3& g) {
  check_magnitude(g, spec_.where + "/gravity", "gravity");
  spec_.gravity = g;
}

void MechanismBuilder::body(const std::string& name, const std::string& parent, JointSpec joint) {
  BodySpec b;
  b.where = spec_.where + "/bodies/" + std::to_string(spec_.bodies.size());
  b.name = name;
  b.parent = parent;
  joint.where = b.where + "/joint";
  for (const Vec3* v : {&joint.xyz, &joint.rpy, &joint.axis})
    check_magnitude(*v, joint.where, "joint origin or axis");
  for (double x : {joint.stiffness, joint.rest, joint.damping})
    check_magnitude(x, joint.where, "joint spring or damper");
  if (joint.stiffness < 0 || joint.damping < 0)
    throw ModelError(joint.where, "stiffness and damping must not be negative");
  check_fixed_joint(joint);
  b.joint = std::move(joint);
  spec_.bodies.push_back(std::move(b));
}

BodySpec& MechanismBuilder::body_named(const std::string& name, const char* what) {
  for (BodySpec& b : spec_.bodies)
    if (b.name == name) return b;
  throw ModelError(spec_.where + what,
                   "unknown body " + quoted_text(name) + " (add it with body() first)");
}

void MechanismBuilder::node(const std::string& body, const std::string& name,
                            const Vec3& position) {
  BodySpec& b = body_named(body, "node");
  const std::string where = b.where + "/nodes/" + name;
  check_name(name, where, "node name");
  if (name.find('/') != std::string::npos)
    throw ModelError(where, "a node name has no '/' (that names a node of another body)");
  check_magnitude(position, where, "node position");
  nodes_[body][name] = position;
}

std::string MechanismBuilder::next_element(const BodySpec& b) const {
  return b.where + "/elements/" + std::to_string(b.elements.size());
}

// As the JSON loader labels them (io/params.cpp): "body/name", "other/name", "body/(x,y,z)".
std::pair<Vec3, std::string> MechanismBuilder::resolve(const BodySpec& b,
                                                       const NodeDescription& node,
                                                       const std::string& where) const {
  if (const Vec3* p = std::get_if<Vec3>(&node)) {
    check_magnitude(*p, where, "node position");
    char buf[96];
    std::snprintf(buf, sizeof buf, "/(%g,%g,%g)", p->x(), p->y(), p->z());
    return {*p, b.name + buf};
  }
  const std::string& name = std::get<std::string>(node);
  const auto cut = name.rfind('/');
  const std::string owner = cut == std::string::npos ? b.name : name.substr(0, cut);
  const std::string local = cut == std::string::npos ? name : name.substr(cut + 1);
  const auto body = nodes_.find(owner);
  if (body == nodes_.end() || !body->second.count(local))
    throw ModelError(where, "unknown node " + quoted_text(name) + " (not in the body's nodes)");
  return {body->second.at(local), cut == std::string::npos ? b.name + "/" + name : name};
}

void MechanismBuilder::lumped_point(const std::string& body, const NodeDescription& node,
                                    double mass) {
  BodySpec& b = body_named(body, "lumped_point");
  const std::string where = next_element(b);
  const auto [p, label] = resolve(b, node, where + "/node");
  check_positive(mass, where + "/mass");
  ElementSink(b.elements, where).add(std::make_unique<LumpedPoint>(p, mass), {label});
}

void MechanismBuilder::rotary_node(const std::string& body, const NodeDescription& node,
                                   const Mat3& inertia) {
  BodySpec& b = body_named(body, "rotary_node");
  const std::string where = next_element(b);
  const auto [p, label] = resolve(b, node, where + "/node");
  check_inertia(inertia, where + "/inertia");
  ElementSink(b.elements, where).add(std::make_unique<RotaryNode>(p, inertia), {label});
}

void MechanismBuilder::rigid_body(const std::string& body, double mass, const Vec3& com,
                                  const Mat3& inertia) {
  BodySpec& b = body_named(body, "rigid_body");
  const std::string where = next_element(b);
  check_positive(mass, where + "/mass");
  check_magnitude(com, where + "/com", "centre of mass");
  check_inertia(inertia, where + "/inertia");
  ElementSink sink(b.elements, where);
  RigidBodyShorthand::point_rotary(mass, com, inertia, sink);
}

MechanismBuilder::BarEnds MechanismBuilder::space_bar_ends(const BodySpec& bs,
                                                           const NodeDescription& a,
                                                           const NodeDescription& b,
                                                           const std::string& where) const {
  auto [pa, la] = resolve(bs, a, where + "/nodes/0");
  auto [pb, lb] = resolve(bs, b, where + "/nodes/1");
  if (!((pb - pa).norm() > 1e-12))
    throw ModelError(where + "/nodes", "the two nodes of a space bar coincide");
  return {pa, std::move(la), pb, std::move(lb)};
}

void MechanismBuilder::space_bar(const std::string& body, const NodeDescription& a,
                                 const NodeDescription& b, double mass, const Mat3& inertia) {
  BodySpec& bs = body_named(body, "space_bar");
  const std::string where = next_element(bs);
  const auto [pa, la, pb, lb] = space_bar_ends(bs, a, b, where);
  check_positive(mass, where + "/mass");
  check_inertia(inertia, where + "/inertia");
  ElementSink(bs.elements, where)
      .add(SpaceBar::from_mass_properties(pa, pb, mass, inertia), {la, lb});
}

void MechanismBuilder::space_bar(const std::string& body, const NodeDescription& a,
                                 const NodeDescription& b, const BarSection& section) {
  BodySpec& bs = body_named(body, "space_bar");
  const std::string where = next_element(bs);
  const auto [pa, la, pb, lb] = space_bar_ends(bs, a, b, where);
  check_positive(section.density, where + "/density");
  check_positive(section.area, where + "/area");
  check_positive(section.Iy, where + "/Iy");
  check_positive(section.Iz, where + "/Iz");
  if (section.section_y) {
    check_magnitude(*section.section_y, where + "/section_y", "section axis");
    if (auto problem = SpaceBar::section_y_problem(pa, pb, *section.section_y))
      throw ModelError(where + "/section_y", *problem);
  }
  ElementSink(bs.elements, where).add(SpaceBar::from_section(pa, pb, section), {la, lb});
}

void MechanismBuilder::flexible_bar(const Json& bar) {
  const std::string where = spec_.where + "/flexible_bars/" + std::to_string(flexible_bars_++);
  FlexibleBarSpec parsed = parse_flexible_bar(default_catalog(), bar, where);
  for (BodySpec& b : parsed.bodies) spec_.bodies.push_back(std::move(b));
  spec_.bars.push_back(std::move(parsed.centreline));
}

void MechanismBuilder::rod(const std::string& body, const NodeDescription& a,
                           const NodeDescription& b, double mass) {
  BodySpec& bs = body_named(body, "rod");
  const std::string where = next_element(bs);
  const auto [pa, la] = resolve(bs, a, where + "/nodes/0");
  const auto [pb, lb] = resolve(bs, b, where + "/nodes/1");
  check_positive(mass, where + "/mass");
  ElementSink(bs.elements, where).add(std::make_unique<Rod>(pa, pb, mass), {la, lb});
}

void MechanismBuilder::coupling(const std::string& joint,
                                const std::vector<std::pair<std::string, double>>& terms,
                                double offset) {
  CouplingSpec c;
  c.where = next_coupling();
  c.joint = joint;
  for (const auto& [name, ratio] : terms) check_magnitude(ratio, c.where + "/follows", "ratio");
  check_magnitude(offset, c.where + "/offset", "offset");
  if (terms.empty())
    throw ModelError(c.where + "/follows", "names no joint (to fix a joint, make it fixed)");
  c.terms = terms;
  c.offset = offset;
  spec_.couplings.push_back(std::move(c));
}

void MechanismBuilder::coupling(const std::string& joint, const std::vector<std::string>& follows,
                                std::shared_ptr<const CouplingFunction> law) {
  CouplingSpec c;
  c.where = next_coupling();
  if (!law) throw ModelError(c.where, "no law given");
  c.joint = joint;
  c.follows = follows;
  c.law = std::move(law);
  spec_.couplings.push_back(std::move(c));
}

std::string MechanismBuilder::next_coupling() const {
  return spec_.where + "/couplings/" + std::to_string(spec_.couplings.size());
}

void MechanismBuilder::coupling(CouplingSpec c) {
  if (c.where.empty()) c.where = next_coupling();
  spec_.couplings.push_back(std::move(c));
}

void MechanismBuilder::constraint(ConstraintSpec c) {
  if (c.where.empty()) c.where = next_constraint();
  spec_.constraints.push_back(std::move(c));
}

void MechanismBuilder::spring(SpringSpec s) {
  if (s.where.empty()) s.where = next_spring();
  spec_.springs.push_back(std::move(s));
}

std::string MechanismBuilder::next_constraint() const {
  return spec_.where + "/constraints/" + std::to_string(spec_.constraints.size());
}

std::string MechanismBuilder::next_spring() const {
  return spec_.where + "/springs/" + std::to_string(spec_.springs.size());
}

void MechanismBuilder::frame(const std::string& name, const std::string& body, const Vec3& xyz,
                             const Vec3& rpy) {
  FrameSpec f;
  f.where = spec_.where + "/frames/" + std::to_string(spec_.frames.size());
  f.name = name;
  f.body = body;
  f.xyz = xyz;
  f.rpy = rpy;
  spec_.frames.push_back(std::move(f));
}

void MechanismBuilder::load(const std::string& body, const Vec3& point, const Vec3& force,
                            const Vec3& torque) {
  LoadSpec l;
  l.where = spec_.where + "/loads/" + std::to_string(spec_.loads.size());
  (void)body_named(body, "load");
  l.body = body;
  check_magnitude(point, l.where + "/point", "load point");
  check_magnitude(force, l.where + "/force", "force");
  check_magnitude(torque, l.where + "/torque", "torque");
  l.point = point;
  l.force = force;
  l.torque = torque;
  spec_.loads.push_back(std::move(l));
}

Model MechanismBuilder::build() const { return compile(spec_); }

}  // namespace femdyn
