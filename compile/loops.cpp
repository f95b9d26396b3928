#include "compile/loops.hpp"

#include <cmath>
#include <set>

#include "core/kinematics/frames.hpp"
#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"

namespace femdyn {

namespace {

Attachment compile_attachment(const AttachmentSpec& s, const Model& m) {
  Attachment A;
  if (!s.frame.empty()) {
    A.name = s.frame;
    if (s.frame == "world") return A;
    const int f = find_frame(m, s.frame);
    if (f < 0)
      throw ModelError(s.where, "unknown frame or body " + quoted_text(s.frame) +
                                    " (give a body, a frame of \"frames\", or \"world\")");
    A.body = m.frames[f].body;
    A.R = m.frames[f].R_BF;
    A.p = m.frames[f].p_BF;
    return A;
  }
  check_magnitude(s.xyz, s.where + "/xyz", "xyz");
  check_magnitude(s.rpy, s.where + "/rpy", "rpy");
  A.name = s.body;
  A.R = rpy_to_rotation(s.rpy);
  A.p = s.xyz;
  if (s.body == "world") return A;
  for (int b = 0; b < static_cast<int>(m.bodies.size()); ++b)
    if (m.bodies[b].name == s.body) {
      A.body = b;
      return A;
    }
  throw ModelError(s.where + "/body", "unknown body " + quoted_text(s.body));
}

// A unit vector from the spec's axis (normal or direction).
Vec3 unit_axis(const ConstraintSpec& c, const char* key) {
  if (!c.axis) throw ModelError(c.where, std::string("needs \"") + key + "\"");
  check_magnitude(*c.axis, c.where + "/" + key, key);
  const double norm = c.axis->norm();
  if (!(norm > 1e-12)) throw ModelError(c.where + "/" + key, "must not be zero");
  return *c.axis / norm;
}

// Two unit axes completing n to an orthonormal basis.
std::vector<Vec3> normal_plane(const Vec3& n) {
  const Vec3 t = n.unitOrthogonal();
  return {t, n.cross(t)};
}

// The θ index (idx_q) and the rate (idx_v) of a named joint of one coordinate.
std::pair<int, int> gear_joint(const Model& m, const std::string& name, const std::string& where) {
  for (const Body& b : m.bodies)
    if (b.joint.name == name) {
      if (b.joint.idx_q < 0) throw ModelError(where, "joint " + quoted_text(name) + " is fixed");
      if (b.joint.nq != 1 || b.joint.nv != 1)
        throw ModelError(where, "joint " + quoted_text(name) +
                                    " has several coordinates: a gear joins joints of one");
      return {b.joint.idx_q, b.joint.idx_v};
    }
  throw ModelError(where, "unknown joint " + quoted_text(name));
}

void compile_gear(const ConstraintSpec& s, const Model& m, LoopConstraint& c) {
  const auto [q, v] = gear_joint(m, s.joint, s.where + "/joint");
  c.joint = q;
  c.offset = s.offset;
  check_magnitude(s.offset, s.where + "/offset", "offset");
  c.gear_rate = m.C.row(v).toDense().transpose();
  if (s.terms.empty()) throw ModelError(s.where + "/follows", "a gear needs a joint to follow");
  for (std::size_t i = 0; i < s.terms.size(); ++i) {
    const auto& [name, ratio] = s.terms[i];
    const std::string where = s.where + "/follows";
    const auto [qi, vi] = gear_joint(m, name, where);
    if (qi == q) throw ModelError(where, "a joint cannot follow itself");
    check_magnitude(ratio, where, "ratio");
    c.terms.emplace_back(qi, ratio);
    c.gear_rate -= ratio * m.C.row(vi).toDense().transpose();
  }
  if (c.gear_rate.isZero(0))
    throw ModelError(s.where,
                     "the gear relates coordinates that are already coupled so: it "
                     "constrains nothing");
}

// The constraint's own geometry: the axes a ball, line or plane constraint removes, a
// distance's length.
void compile_constraint_geometry(const ConstraintSpec& s, LoopConstraint& c) {
  switch (c.type) {
    case ConstraintType::Ball:
      if (s.axis) c.axes = normal_plane(unit_axis(s, "normal"));
      break;
    case ConstraintType::PointOnLine:
      c.axes = normal_plane(unit_axis(s, "direction"));
      break;
    case ConstraintType::PointOnPlane:
      c.axes = {unit_axis(s, "normal")};
      break;
    case ConstraintType::Distance:
      check_magnitude(s.length, s.where + "/length", "length");
      if (!(s.length > 0)) throw ModelError(s.where + "/length", "must be a positive length");
      c.length = s.length;
      break;
    case ConstraintType::Weld:
    case ConstraintType::Gear:
      break;
  }
}

LoopConstraint compile_constraint(const ConstraintSpec& s, const Model& m) {
  check_name(s.name, s.where + "/name", "constraint name");  // (printed by info, check, reports)
  LoopConstraint c;
  c.name = s.name;
  c.where = s.where;
  if (!parse_constraint_type(s.type, c.type))
    throw ModelError(s.where + "/type",
                     "unknown constraint type " + quoted_text(s.type) +
                         " (ball, weld, distance, point_on_line, point_on_plane, gear)");
  if (c.type == ConstraintType::Gear) {
    compile_gear(s, m, c);
    return c;
  }
  c.a = compile_attachment(s.a, m);
  c.b = compile_attachment(s.b, m);
  if (c.a.body == c.b.body)
    throw ModelError(s.where, "both ends are on " +
                                  (c.a.body < 0 ? std::string("the world")
                                                : "body " + quoted_text(m.bodies[c.a.body].name)) +
                                  ": a constraint closes a loop between two bodies");
  compile_constraint_geometry(s, c);
  return c;
}

TwoPointSpring compile_spring(const SpringSpec& s, const Model& m) {
  check_name(s.name, s.where + "/name", "spring name");
  TwoPointSpring k;
  k.name = s.name;
  k.where = s.where;
  k.a = compile_attachment(s.a, m);
  k.b = compile_attachment(s.b, m);
  if (k.a.body == k.b.body)
    throw ModelError(s.where, "both ends are on the same body: the spring would do nothing");
  for (const auto& [value, key] :
       {std::pair{s.stiffness, "stiffness"}, std::pair{s.rest_length, "rest_length"},
        std::pair{s.damping, "damping"}}) {
    check_magnitude(value, s.where + "/" + key, key);
    if (!(value >= 0)) throw ModelError(s.where + "/" + key, "must be >= 0");
  }
  k.stiffness = s.stiffness;
  k.rest_length = s.rest_length;
  k.damping = s.damping;
  return k;
}

}  // namespace

void compile_loops(const MechanismSpec& spec, Model& m) {
  std::set<std::string> names;
  for (const ConstraintSpec& s : spec.constraints) {
    m.constraints.push_back(compile_constraint(s, m));
    if (!names.insert(s.name).second)
      throw ModelError(s.where + "/name", "duplicate constraint name " + quoted_text(s.name));
    m.constraint_rows += m.constraints.back().rows();
  }
  names.clear();
  for (const SpringSpec& s : spec.springs) {
    m.springs.push_back(compile_spring(s, m));
    if (!names.insert(s.name).second)
      throw ModelError(s.where + "/name", "duplicate spring name " + quoted_text(s.name));
  }
}

}  // namespace femdyn
