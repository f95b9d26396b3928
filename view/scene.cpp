#include "view/scene.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/errors.hpp"
#include "core/joints/joint_type.hpp"
#include "core/kinematics.hpp"
#include "core/workspace.hpp"

namespace femdyn::view {
namespace {

// Positions to the micrometre and unit quaternions to 1e-6: the page draws, it does not compute.
double rounded(double x) { return std::round(x * 1e6) / 1e6; }

Json vec_json(const Eigen::Ref<const VecX>& v) {
  Json out = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(rounded(v[i]));
  return out;
}

// [x, y, z, w], as three.js orders a quaternion.
Json quaternion_json(const Mat3& R) {
  const Eigen::Quaterniond q(R);
  return vec_json(Eigen::Vector4d(q.x(), q.y(), q.z(), q.w()));
}

int body_named(const Model& m, const std::string& name) {
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (m.bodies[b].name == name) return static_cast<int>(b);
  return -1;
}

Json body_json(const Body& b) {
  const Joint& j = b.joint;
  return {{"name", b.name},
          {"parent", b.parent},
          {"joint",
           {{"name", j.name},
            {"type", std::string(joint_type_name(j.type))},
            {"dofs", j.nv},
            {"origin", vec_json(j.p_pj)},  // in the parent's frame
            {"axis", vec_json(j.axis)},    // in the body (joint) frame
            {"axis2", vec_json(j.axis2)}}}};
}

// Mass, centre of mass and principal inertia (moments and axes as columns, body frame).
Json element_json(const ElementEntry& e) {
  const MassProperties mp = e.element->mass_properties();
  const Eigen::SelfAdjointEigenSolver<Mat3> principal(mp.inertia_com());
  Json nodes = Json::array();
  const auto element_nodes = e.element->nodes();
  for (std::size_t l = 0; l < element_nodes.size(); ++l)
    nodes.push_back({{"body", e.node_body[l]},
                     {"label", l < e.node_labels.size() ? e.node_labels[l] : ""},
                     {"p", vec_json(element_nodes[l].position)}});
  return {{"type", std::string(e.element->type_name())},
          {"body", e.body},
          {"mass", mp.mass},
          {"com", vec_json(mp.com)},
          {"moments", vec_json(principal.eigenvalues())},
          {"axes", quaternion_json(principal.eigenvectors().determinant() < 0
                                       ? Mat3(-principal.eigenvectors())
                                       : Mat3(principal.eigenvectors()))},
          {"nodes", nodes}};
}

Json visual_json(const Model& m, const UrdfVisual& v) {
  Json out = {{"body", body_named(m, v.link)},
              {"link", v.link},
              {"shape", v.shape},
              {"size", vec_json(v.size)},
              {"p", vec_json(v.xyz)},
              {"quaternion", quaternion_json(rpy_to_rotation(v.rpy))}};
  if (!v.mesh.empty()) out["mesh"] = v.mesh;
  if (v.rgba) out["rgba"] = vec_json(*v.rgba);
  return out;
}

// Each body's pose at q, [x y z qx qy qz qw] body after body, from the model's kinematics.
Json poses_json(const Model& m, Workspace& ws, const VecX& q, double t) {
  propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = false, .bias = false, .rows = false});
  Json out = Json::array();
  for (const BodyState& B : ws.body) {
    if (!B.p.allFinite() || !B.R.allFinite())
      throw StateError("the pose at t = " + std::to_string(t) + " is NaN or Inf");
    for (const Json& x : vec_json(Vec3(ws.origin + B.p))) out.push_back(x);
    for (const Json& x : quaternion_json(B.R)) out.push_back(x);
  }
  return out;
}

Json motion_json(const Model& m, const Motion& motion) {
  Workspace ws(m);
  Json t = Json::array(), poses = Json::array(), q = Json::array(), kinetic = Json::array(),
       potential = Json::array(), work = Json::array();
  for (const MotionFrame& f : motion.frames) {
    t.push_back(f.t);
    poses.push_back(poses_json(m, ws, f.q, f.t));
    q.push_back(vec_json(f.q));
    kinetic.push_back(f.kinetic);
    potential.push_back(f.potential);
    work.push_back(f.work);
  }
  return {{"trajectory", motion.trajectory},
          {"t", t},
          {"poses", poses},
          {"q", q},
          {"energy",
           {{"source", motion.energy_source},
            {"kinetic", kinetic},
            {"potential", potential},
            {"work", work}}}};
}

}  // namespace

Json scene_json(const Model& m, const Motion& motion, const std::vector<UrdfVisual>& visuals,
                const std::string& source) {
  Json bodies = Json::array(), frames = Json::array(), elements = Json::array(),
       shapes = Json::array();
  for (const Body& b : m.bodies) bodies.push_back(body_json(b));
  for (std::size_t f = m.bodies.size(); f < m.frames.size(); ++f)
    frames.push_back({{"name", m.frames[f].name},
                      {"body", m.frames[f].body},
                      {"p", vec_json(m.frames[f].p_BF)},
                      {"quaternion", quaternion_json(m.frames[f].R_BF)}});
  for (const ElementEntry& e : m.elements) elements.push_back(element_json(e));
  for (const UrdfVisual& v : visuals) shapes.push_back(visual_json(m, v));
  int joints = 0;
  for (const Body& b : m.bodies) joints += b.joint.type != JointType::Fixed;
  return {{"model", m.name},
          {"source", source},
          {"gravity", vec_json(m.gravity)},
          {"coordinates", m.configuration_names},
          {"bodies", bodies},
          {"frames", frames},
          {"elements", elements},
          {"visuals", shapes},
          {"motion", motion_json(m, motion)},
          {"counts",
           {{"bodies", bodies.size()},
            {"joints", joints},
            {"elements", elements.size()},
            {"frames", frames.size()},
            {"visuals", shapes.size()},
            {"motion_frames", motion.frames.size()}}}};
}

}  // namespace femdyn::view
