// <equality> as femdyn's constraints and couplings (mjcf_reading.hpp: read_equalities).
//   connect body1 body2 anchor -> a ball constraint: the anchor (body1's frame) and the point of
//     body2 that coincides with it in the model as written (qpos0).
//   weld body1 body2 [relpose] -> a weld: body2's frame at relpose in body1's (as written
//     without one).
//   joint joint1 joint2 polycoef a0…a4 -> a coupling, y − y0 = Σ a_k (x − x0)^k with y, x the two
//     joints' qpos and y0, x0 their refs: linear, or the polynomial expanded in x.
//   tendon tendon1 [tendon2] polycoef a0 a1 -> a linear coupling among the fixed tendons' joints
//     (tendon_coupling).
// MuJoCo keeps equalities soft (solref, solimp); femdyn's hold exactly (docs/loops.md).
#include <algorithm>
#include <cstring>

#include "core/model/names.hpp"
#include "io/mjcf_reading.hpp"

namespace femdyn::mjcf {

Vec3 rotation_rpy(const Mat3& R) {
  const double c = std::hypot(R(0, 0), R(1, 0));
  if (c > 1e-9)
    return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), c), std::atan2(R(1, 0), R(0, 0))};
  return {std::atan2(-R(1, 2), R(1, 1)), std::atan2(-R(2, 0), c), 0.0};
}

namespace {

const PlacedBody& body_named(const Document& doc, const Tree& tree, const XMLElement& e,
                             const char* attr, bool world_default) {
  const char* name = e.Attribute(attr);
  if (!name && world_default) return tree.bodies.at("world");
  if (!name) doc.fail(e, std::string("needs ") + attr);
  const auto it = tree.bodies.find(name);
  if (it == tree.bodies.end()) doc.fail(e, std::string(attr) + ": no body " + quoted_text(name));
  return it->second;
}

// A place on a femdyn body: a point given in the MuJoCo body's frame, with axes turned by R.
Json place(const PlacedBody& b, const Vec3& point, const Mat3& R = Mat3::Identity()) {
  Json p = {{"body", b.femdyn}, {"xyz", vec3_json(point - b.shift)}};
  if (!R.isIdentity(0)) p["rpy"] = vec3_json(rotation_rpy(R));
  return p;
}

Json connect(const Document& doc, const Tree& tree, const XMLElement& e) {
  const PlacedBody& b1 = body_named(doc, tree, e, "body1", false);
  const PlacedBody& b2 = body_named(doc, tree, e, "body2", true);
  const Vec3 anchor = doc.vec3(e, "anchor", "", Vec3::Constant(NAN));
  if (!anchor.allFinite()) doc.fail(e, "needs anchor (femdyn reads a connect between bodies)");
  const Vec3 world = b1.world0.p + b1.world0.R * anchor;
  const Vec3 in2 = b2.world0.R.transpose() * (world - b2.world0.p);
  return {{"type", "ball"}, {"a", place(b1, anchor)}, {"b", place(b2, in2)}};
}

Json weld(const Document& doc, const Tree& tree, const XMLElement& e) {
  const PlacedBody& b1 = body_named(doc, tree, e, "body1", false);
  const PlacedBody& b2 = body_named(doc, tree, e, "body2", true);
  Pose rel{b1.world0.R.transpose() * (b2.world0.p - b1.world0.p),
           b1.world0.R.transpose() * b2.world0.R};
  if (const std::vector<double> r = doc.numbers(e, "relpose", "", 7);
      !r.empty() && Eigen::Vector4d(r[3], r[4], r[5], r[6]).norm() > 0)
    rel = {Vec3(r[0], r[1], r[2]),
           Eigen::Quaterniond(r[3], r[4], r[5], r[6]).normalized().toRotationMatrix()};
  return {{"type", "weld"}, {"a", place(b1, rel.p, rel.R)}, {"b", place(b2, Vec3::Zero())}};
}

const PlacedJoint& joint_named(const Document& doc, const Tree& tree, const XMLElement& e,
                               const char* attr) {
  const char* name = e.Attribute(attr);
  if (!name)
    doc.fail(e, std::string("needs ") + attr + " (femdyn holds a joint by following another)");
  const auto it = tree.joints.find(name);
  if (it == tree.joints.end()) doc.fail(e, std::string(attr) + ": no joint " + quoted_text(name));
  if (it->second.type != "hinge" && it->second.type != "slide")
    doc.fail(e, std::string(attr) + ": a " + it->second.type + " joint (hinge or slide only)");
  return it->second;
}

// y = y0 + Σ a_k (x − x0)^k, expanded in powers of x.
Json joint_coupling(const Document& doc, const Tree& tree, const XMLElement& e) {
  const PlacedJoint& y = joint_named(doc, tree, e, "joint1");
  const PlacedJoint& x = joint_named(doc, tree, e, "joint2");
  std::vector<double> a = doc.numbers(e, "polycoef", "", 5);
  if (a.empty()) a = {0, 1, 0, 0, 0};
  std::vector<double> c(5, 0.0);  // c_i: the coefficient of x^i
  for (int k = 0; k < 5; ++k) {
    double binomial = 1;
    for (int i = 0; i <= k; ++i) {  // C(k, i) x^i (−x0)^(k−i)
      c[static_cast<std::size_t>(i)] +=
          a[static_cast<std::size_t>(k)] * binomial * std::pow(-x.ref, k - i);
      binomial = binomial * (k - i) / (i + 1);
    }
  }
  c[0] += y.ref;
  Json coupling = {{"joint", y.femdyn_joint}, {"follows", x.femdyn_joint}};
  if (c[2] == 0 && c[3] == 0 && c[4] == 0) {
    coupling["ratio"] = c[1];
    coupling["offset"] = c[0];
    return coupling;
  }
  Json terms = Json::array();
  for (int i = 0; i < 5; ++i)
    if (c[static_cast<std::size_t>(i)] != 0) terms.push_back({c[static_cast<std::size_t>(i)], i});
  coupling["polynomial"] = terms;
  return coupling;
}

// A <fixed> tendon's joints and coefficients, L = Σ a_i q_i.
std::vector<std::pair<const PlacedJoint*, double>> fixed_tendon(const Document& doc,
                                                                const Tree& tree,
                                                                const XMLElement& e,
                                                                const char* attr) {
  const char* name = e.Attribute(attr);
  if (!name) doc.fail(e, std::string("needs ") + attr);
  for (const XMLElement* section : doc.sections("tendon"))
    for (const XMLElement* t : doc.children(*section)) {
      if (!t->Attribute("name", name)) continue;
      if (std::strcmp(t->Name(), "fixed") != 0)
        doc.fail(e, std::string(attr) + ": tendon " + quoted_text(name) +
                        " is spatial (femdyn reads an equality on fixed tendons)");
      std::vector<std::pair<const PlacedJoint*, double>> out;
      for (const XMLElement* j : doc.children(*t, "joint"))
        out.push_back({&joint_named(doc, tree, *j, "joint"), doc.number(*j, "coef", "", 0)});
      if (out.empty()) doc.fail(*t, "a fixed tendon without joints");
      return out;
    }
  doc.fail(e, std::string(attr) + ": no tendon " + quoted_text(name));
}

// tendon tendon1 [tendon2] polycoef p: L1 − L1₀ = p0 + p1 (L2 − L2₀) on fixed tendons (L₀ their
// lengths at qpos0): a linear relation among their joints, held by making tendon1's first joint
// that tendon2 does not hold follow the others. A nonlinear polycoef is refused.
Json tendon_coupling(const Document& doc, const Tree& tree, const XMLElement& e) {
  std::vector<double> p = doc.numbers(e, "polycoef", "", 5);
  if (p.empty()) p = {0, 1, 0, 0, 0};
  if (p[2] != 0 || p[3] != 0 || p[4] != 0)
    doc.fail(e, "a nonlinear tendon equality (femdyn reads polycoef a0 a1 0 0 0)");
  const auto t1 = fixed_tendon(doc, tree, e, "tendon1");
  const auto t2 = e.Attribute("tendon2") ? fixed_tendon(doc, tree, e, "tendon2")
                                         : std::vector<std::pair<const PlacedJoint*, double>>{};
  // Σ_i a_i q_i − p1 Σ_j b_j q_j = c, c = L1₀ + p0 − p1 L2₀, gathered per joint.
  std::vector<std::pair<const PlacedJoint*, double>> k;
  const auto add = [&](const PlacedJoint* j, double x) {
    for (auto& [jj, kk] : k)
      if (jj == j) return void(kk += x);
    k.push_back({j, x});
  };
  double c = p[0];
  for (const auto& [j, a] : t1) add(j, a), c += a * j->ref;
  if (!t2.empty())
    for (const auto& [j, b] : t2) add(j, -p[1] * b), c -= p[1] * b * j->ref;
  const auto follower =
      std::find_if(k.begin(), k.end(), [](const auto& t) { return t.second != 0; });
  if (follower == k.end()) doc.fail(e, "the tendons' joints cancel: no joint to hold");
  Json follows = Json::array();
  for (const auto& [j, x] : k)
    if (j != follower->first && x != 0)
      follows.push_back({{"joint", j->femdyn_joint}, {"ratio", -x / follower->second}});
  if (follows.empty()) doc.fail(e, "holds one joint at a constant (femdyn holds it by a coupling)");
  return {{"joint", follower->first->femdyn_joint},
          {"follows", follows},
          {"offset", c / follower->second}};
}

}  // namespace

void read_equalities(const Document& doc, const Tree& tree, Json& model,
                     std::vector<std::string>& notes) {
  for (const XMLElement* section : doc.sections("equality"))
    for (const XMLElement* e : doc.children(*section)) {
      if (!doc.flag(*e, "active", doc.class_of(*e, ""), true)) {
        notes.push_back(doc.file_of(*e) + ": " + doc.who(*e) + ": inactive, not read");
        continue;
      }
      const std::string tag = e->Name();
      Json item;
      if (tag == "connect")
        item = connect(doc, tree, *e);
      else if (tag == "weld")
        item = weld(doc, tree, *e);
      else if (tag == "joint")
        item = joint_coupling(doc, tree, *e);
      else if (tag == "tendon")
        item = tendon_coupling(doc, tree, *e);
      else
        doc.fail(*e,
                 "an equality femdyn does not read yet (connect, weld, joint and tendon "
                 "are read)");
      const bool coupling = tag == "joint" || tag == "tendon";
      if (const char* name = e->Attribute("name"); name && !coupling) item["name"] = name;
      model[coupling ? "couplings" : "constraints"].push_back(item);
    }
}

}  // namespace femdyn::mjcf
