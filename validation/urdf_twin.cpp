// The independent URDF twin (urdf_twin.hpp). C++17, without NDEBUG (see twin.cpp).
#include "validation/urdf_twin.hpp"

#include <Simbody.h>
#include <tinyxml2.h>

#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/errors.hpp"

namespace femdyn::validation {

namespace {

using namespace SimTK;

Vec3 triple(const tinyxml2::XMLElement* e, const char* attr, const Vec3& fallback) {
  const char* s = e ? e->Attribute(attr) : nullptr;
  if (!s) return fallback;
  std::istringstream in(s);
  Vec3 v;
  in >> v[0] >> v[1] >> v[2];
  return v;
}

double number(const tinyxml2::XMLElement* e, const char* attr, double fallback) {
  return e && e->Attribute(attr) ? e->DoubleAttribute(attr) : fallback;
}

// URDF origin: xyz, and rpy = roll about x, then pitch about y, then yaw about z, all about the
// fixed (space) axes — Simbody's space-fixed X-Y-Z sequence.
Transform origin(const tinyxml2::XMLElement* parent) {
  const tinyxml2::XMLElement* o = parent ? parent->FirstChildElement("origin") : nullptr;
  const Vec3 xyz = triple(o, "xyz", Vec3(0)), rpy = triple(o, "rpy", Vec3(0));
  return Transform(Rotation(SpaceRotationSequence, rpy[0], XAxis, rpy[1], YAxis, rpy[2], ZAxis),
                   xyz);
}

// <inertial>: mass, centre of mass at the origin's xyz, inertia about the centre of mass in the
// <inertial> frame; Simbody wants it about the link origin in the link frame.
MassProperties mass_properties(const tinyxml2::XMLElement* link) {
  const tinyxml2::XMLElement* in = link->FirstChildElement("inertial");
  if (!in) return MassProperties(0, Vec3(0), Inertia(0));
  const double m = number(in->FirstChildElement("mass"), "value", 0);
  const tinyxml2::XMLElement* ie = in->FirstChildElement("inertia");
  const Inertia I_inertial(number(ie, "ixx", 0), number(ie, "iyy", 0), number(ie, "izz", 0),
                           number(ie, "ixy", 0), number(ie, "ixz", 0), number(ie, "iyz", 0));
  const Transform X_LI = origin(in);
  if (m == 0) return MassProperties(0, Vec3(0), Inertia(0));
  const Inertia Ic_L = I_inertial.reexpress(~X_LI.R());  // expressed in the link frame
  return MassProperties(m, X_LI.p(), Ic_L.shiftFromMassCenter(-X_LI.p(), m));
}

}  // namespace

struct UrdfTwin::Impl {
  MultibodySystem system;
  SimbodyMatterSubsystem matter{system};
  GeneralForceSubsystem forces{system};
  std::map<std::string, MobilizedBody> joint_body;  // movable joint -> its mobilized body
  struct Mimic {
    std::string leader;
    double k, offset;
  };
  std::map<std::string, Mimic> mimic;
  MobilizedBody base;  // the root's Free mobilizer, with a floating root
  bool floating = false;
  State state;
};

UrdfTwin::UrdfTwin(const std::string& path, const Eigen::Vector3d& gravity, bool floating)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.floating = floating;
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS)
    throw femdyn::Error(path + ": cannot read");
  const tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw femdyn::Error(path + ": no <robot>");
  std::map<std::string, const tinyxml2::XMLElement*> links, joint_to_child;
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link"))
    links[l->Attribute("name")] = l;
  std::map<std::string, std::vector<const tinyxml2::XMLElement*>> children;  // parent link
  for (auto* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
    children[j->FirstChildElement("parent")->Attribute("link")].push_back(j);
    joint_to_child[j->FirstChildElement("child")->Attribute("link")] = j;
  }
  std::string root;
  for (const auto& [name, l] : links)
    if (!joint_to_child.count(name)) root = name;
  // Build from the root outwards; a floating root carries its own <inertial>.
  MobilizedBody root_body = s.matter.updGround();
  if (floating)
    root_body = s.base =
        MobilizedBody::Free(s.matter.updGround(), Transform(),
                            Body::Rigid(mass_properties(links.at(root))), Transform());
  std::vector<std::pair<std::string, MobilizedBody>> todo{{root, root_body}};
  while (!todo.empty()) {
    auto [link, parent] = todo.back();
    todo.pop_back();
    for (const tinyxml2::XMLElement* j : children[link]) {
      const std::string name = j->Attribute("name"), type = j->Attribute("type");
      const std::string child = j->FirstChildElement("child")->Attribute("link");
      const Body::Rigid body(mass_properties(links.at(child)));
      const Transform X_PJ = origin(j);
      Vec3 axis = triple(j->FirstChildElement("axis"), "xyz", Vec3(1, 0, 0));
      MobilizedBody mb;
      if (type == "floating" || type == "planar")  // (femdyn's own twin checks those joints)
        throw femdyn::Error(path + ": joint '" + name + "': the independent URDF twin models no " +
                            type + " joint");
      if (type == "fixed") {
        mb = MobilizedBody::Weld(parent, X_PJ, body, Transform());
      } else if (type == "prismatic") {
        const Rotation R_a(UnitVec3(axis), XAxis);  // Slider moves along x
        mb = MobilizedBody::Slider(parent, Transform(X_PJ.R() * R_a, X_PJ.p()), body,
                                   Transform(R_a, Vec3(0)));
      } else {                                      // revolute, continuous
        const Rotation R_a(UnitVec3(axis), ZAxis);  // Pin turns about z
        mb = MobilizedBody::Pin(parent, Transform(X_PJ.R() * R_a, X_PJ.p()), body,
                                Transform(R_a, Vec3(0)));
      }
      if (type != "fixed") {
        s.joint_body[name] = mb;
        const double c = number(j->FirstChildElement("dynamics"), "damping", 0);
        if (c != 0) Force::MobilityLinearDamper(s.forces, mb, MobilizerUIndex(0), c);
        if (const auto* mim = j->FirstChildElement("mimic"))
          s.mimic[name] = {mim->Attribute("joint"), number(mim, "multiplier", 1),
                           number(mim, "offset", 0)};
      }
      todo.emplace_back(child, mb);
    }
  }
  if (gravity.norm() > 0)
    Force::Gravity(s.forces, s.matter, UnitVec3(Vec3(gravity.x(), gravity.y(), gravity.z())),
                   gravity.norm());
  s.state = s.system.realizeTopology();
}

UrdfTwin::~UrdfTwin() = default;

UrdfTwinEquations UrdfTwin::equations(const std::vector<std::string>& names,
                                      const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  Impl& s = *impl_;
  // nb rates of the floating root come first; then the named coordinates, at q index nb + 1 + a
  // (after the quaternion's extra entry) and rate index nb + a.
  const int nb = s.floating ? 6 : 0, nqb = s.floating ? 7 : 0;
  const int n = nb + static_cast<int>(names.size()), nu = s.state.getNU();
  // u = C v and θ(q): a coordinate drives its joint; a mimic joint follows its leader; the
  // Free mobilizer's u = (ω, v) in the world is (R ω_b, R v_b) of femdyn's rates in body axes.
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(nu, n);
  Eigen::VectorXd Cdot_v = Eigen::VectorXd::Zero(nu);  // Ċ v
  const Eigen::VectorXd q_named = q.tail(q.size() - nqb);
  if (s.floating) {
    const Eigen::Quaterniond quat(q[3], q[4], q[5], q[6]);
    const Eigen::Matrix3d R = quat.normalized().toRotationMatrix();
    const int u0 = s.base.getFirstUIndex(s.state), q0 = s.base.getFirstQIndex(s.state);
    for (int k = 0; k < 4; ++k) s.state.updQ()[q0 + k] = q[3 + k];  // Simbody: (quaternion, p)
    for (int k = 0; k < 3; ++k) s.state.updQ()[q0 + 4 + k] = q[k];
    C.block<3, 3>(u0, 3) = R;      // ω
    C.block<3, 3>(u0 + 3, 0) = R;  // v
    // d(R v_b)/dt = R v̇_b + R (ω_b × v_b); R ω_b has no such term (ω_b × ω_b = 0).
    Cdot_v.segment<3>(u0 + 3) = R * qd.segment<3>(3).cross(qd.head<3>());
  }
  Eigen::VectorXd theta0 = Eigen::VectorXd::Zero(nu);
  std::map<std::string, int> coordinate;
  for (int a = nb; a < n; ++a) coordinate[names[a - nb]] = a;
  std::function<void(const std::string&, Eigen::RowVectorXd&, double&)> resolve =
      [&](const std::string& joint, Eigen::RowVectorXd& row, double& offset) {
        if (coordinate.count(joint)) {
          row = Eigen::RowVectorXd::Zero(n);
          row[coordinate[joint]] = 1;
          offset = 0;
          return;
        }
        const Impl::Mimic& m = s.mimic.at(joint);
        resolve(m.leader, row, offset);
        row *= m.k;
        offset = m.k * offset + m.offset;
      };
  for (const auto& [joint, mb] : s.joint_body) {
    Eigen::RowVectorXd row;
    double offset = 0;
    resolve(joint, row, offset);
    const int u = mb.getFirstUIndex(s.state);
    C.row(u) = row;
    theta0[u] = offset;
    s.state.updQ()[mb.getFirstQIndex(s.state)] =
        row.tail(n - nb).dot(q_named) + offset;  // Pin, Slider: q = θ
  }
  {
    const Eigen::VectorXd u = C * qd;
    for (int a = 0; a < nu; ++a) s.state.updU()[a] = u[a];
  }
  s.system.realize(s.state, Stage::Dynamics);
  Matrix M;
  s.matter.calcM(s.state, M);
  Vector zero(nu, 0.0), bias, with_forces;
  const Vector_<SpatialVec> no_body(s.matter.getNumBodies(), SpatialVec(Vec3(0), Vec3(0)));
  s.matter.calcResidualForceIgnoringConstraints(s.state, zero, no_body, zero, bias);
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, Stage::Dynamics), zero, with_forces);
  Eigen::MatrixXd Mt(nu, nu);
  Eigen::VectorXd ht(nu), Qt(nu);
  for (int a = 0; a < nu; ++a) {
    ht[a] = bias[a];
    Qt[a] = bias[a] - with_forces[a];
    for (int b = 0; b < nu; ++b) Mt(a, b) = M(a, b);
  }
  // M_v = Cᵀ M C, h_v = Cᵀ (h + M Ċ v), Q_v = Cᵀ Q.
  return {C.transpose() * Mt * C, C.transpose() * (ht + Mt * Cdot_v), C.transpose() * Qt};
}

}  // namespace femdyn::validation
