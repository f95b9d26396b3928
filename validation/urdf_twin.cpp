// The independent URDF twin (urdf_twin.hpp). C++17, without NDEBUG (see twin.cpp).
#include "validation/urdf_twin.hpp"

#include <Simbody.h>
#include <tinyxml2.h>

#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include "core/model/errors.hpp"
#include "core/spatial/inertia.hpp"
#include "io/centroidal_mass.hpp"
#include "validation/twin_friction.hpp"

namespace femdyn::validation {

// Simbody's small vectors here, not femdyn's Eigen ones (core/spatial/math.hpp, seen through
// inertia.hpp).
using Vec3 = SimTK::Vec3;
using Mat33 = SimTK::Mat33;

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

// A link's <inertial> in the link frame, as plain matrices: Simbody's Inertia checks each
// tensor it is given, and a sensor or dummy link welded to a body need not be physical on its
// own (the body it is welded into must be). Mass m, centre of mass c, inertia about c.
struct LinkMass {
  double m = 0;
  Mat33 Ic{0};
  Vec3 c{0};
};

LinkMass link_mass(const tinyxml2::XMLElement* link) {
  const tinyxml2::XMLElement* in = link ? link->FirstChildElement("inertial") : nullptr;
  if (!in) return {};
  const tinyxml2::XMLElement* ie = in->FirstChildElement("inertia");
  Mat33 I;
  I(0, 0) = number(ie, "ixx", 0), I(1, 1) = number(ie, "iyy", 0), I(2, 2) = number(ie, "izz", 0);
  I(0, 1) = I(1, 0) = number(ie, "ixy", 0);
  I(0, 2) = I(2, 0) = number(ie, "ixz", 0);
  I(1, 2) = I(2, 1) = number(ie, "iyz", 0);
  const Transform X_LI = origin(in);
  return {number(in->FirstChildElement("mass"), "value", 0), X_LI.R() * I * ~X_LI.R(), X_LI.p()};
}

// Two parts of one rigid body, both in its head's frame: masses add, the centre of mass is
// their mean, each inertia moves to it by the parallel-axis theorem.
LinkMass welded_pair(const LinkMass& a, const LinkMass& b) {
  LinkMass out;
  out.m = a.m + b.m;
  out.c = out.m > 0 ? (a.m * a.c + b.m * b.c) / out.m : a.c;
  out.Ic = a.Ic + b.Ic;
  for (const LinkMass* part : {&a, &b}) {
    const Vec3 d = part->c - out.c;
    out.Ic += part->m * (Mat33(dot(d, d)) - d * ~d);
  }
  return out;
}

// A rigid body's mass properties for Simbody (about its frame's origin), made physical the way
// the import is: within round-off (1e-9 m L²) the nearest physical tensor, and with
// `balance` the nearest physical tensor at any distance (io/centroidal_mass.hpp).
MassProperties simbody_mass(const std::string& link, const LinkMass& lm, double length,
                            bool balance) {
  ::Eigen::Matrix3d I;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) I(r, k) = lm.Ic(r, k);
  if (const auto problem = femdyn::inertia_problem(I, lm.m * length * length); problem && !balance)
    throw femdyn::Error("link '" + link + "': " + *problem);
  I = femdyn::nearest_physical_inertia(I);
  Mat33 Ic;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) Ic(r, k) = I(r, k);
  if (lm.m == 0) return MassProperties(0, Vec3(0), Inertia(0));  // (as a massless link)
  return MassProperties(lm.m, lm.c, Inertia(Ic).shiftFromMassCenter(-lm.c, lm.m));
}

}  // namespace

struct UrdfTwin::Impl {
  MultibodySystem system;
  SimbodyMatterSubsystem matter{system};
  GeneralForceSubsystem forces{system};
  // A movable joint: its URDF type ("revolute", "continuous", "prismatic", "planar" or
  // "floating"; a floating root is one named after its link) and its mobilized body.
  struct Joint {
    std::string name, type;
    MobilizedBody body;
  };
  std::vector<Joint> joints;
  struct Mimic {
    std::string leader;
    double k, offset;
  };
  std::map<std::string, Mimic> mimic;
  State state;

  // Simbody's M, h and Q at `state` (u set), reduced to femdyn's rates v by u = C v:
  // M_v = Cᵀ M C, h_v = Cᵀ (h + M Ċ v), Q_v = Cᵀ Q.
  UrdfTwinEquations reduced_equations(const ::Eigen::MatrixXd& C, const ::Eigen::VectorXd& Cdot_v) {
    const int nu = state.getNU();
    system.realize(state, Stage::Dynamics);
    Matrix M;
    matter.calcM(state, M);
    Vector zero(nu, 0.0), bias, with_forces;
    const Vector_<SpatialVec> no_body(matter.getNumBodies(), SpatialVec(Vec3(0), Vec3(0)));
    matter.calcResidualForceIgnoringConstraints(state, zero, no_body, zero, bias);
    matter.calcResidualForceIgnoringConstraints(
        state, system.getMobilityForces(state, Stage::Dynamics),
        system.getRigidBodyForces(state, Stage::Dynamics), zero, with_forces);
    ::Eigen::MatrixXd Mt(nu, nu);
    ::Eigen::VectorXd ht(nu), Qt(nu);
    for (int a = 0; a < nu; ++a) {
      ht[a] = bias[a];
      Qt[a] = bias[a] - with_forces[a];
      for (int b = 0; b < nu; ++b) Mt(a, b) = M(a, b);
    }
    // M_v = Cᵀ M C, h_v = Cᵀ (h + M Ċ v), Q_v = Cᵀ Q.
    return {C.transpose() * Mt * C, C.transpose() * (ht + Mt * Cdot_v), C.transpose() * Qt};
  }
};

namespace {

// The in-plane axes of a URDF planar joint about its normal n (docs/model-format.md, "planar"):
// e₁ the joint frame's x made normal to n (its y when x is nearly along n), e₂ = n × e₁, as the
// columns of the frame (e₁, e₂, n) in which Simbody's Planar mobilizer turns about z.
Rotation planar_frame(const Vec3& normal) {
  const UnitVec3 n(normal);
  Vec3 x(1, 0, 0);
  if (std::abs(dot(x, n)) >= 0.9) x = Vec3(0, 1, 0);
  const UnitVec3 e1(x - dot(x, n) * n);
  const UnitVec3 e2(cross(n, e1));
  Mat33 R;
  R.col(0) = e1.asVec3();
  R.col(1) = e2.asVec3();
  R.col(2) = n.asVec3();
  return Rotation(R, true);
}

MobilizedBody mobilize(MobilizedBody& parent, const std::string& type, const Transform& X_PJ,
                       const Vec3& axis, const Body::Rigid& body) {
  if (type == "fixed") return MobilizedBody::Weld(parent, X_PJ, body, Transform());
  if (type == "floating") return MobilizedBody::Free(parent, X_PJ, body, Transform());
  if (type == "spherical") return MobilizedBody::Ball(parent, X_PJ, body, Transform());
  if (type == "planar") {
    const Rotation R_a = planar_frame(axis);
    return MobilizedBody::Planar(parent, Transform(X_PJ.R() * R_a, X_PJ.p()), body,
                                 Transform(R_a, Vec3(0)));
  }
  if (type == "prismatic") {
    const Rotation R_a(UnitVec3(axis), XAxis);  // Slider moves along x
    return MobilizedBody::Slider(parent, Transform(X_PJ.R() * R_a, X_PJ.p()), body,
                                 Transform(R_a, Vec3(0)));
  }
  const Rotation R_a(UnitVec3(axis), ZAxis);  // revolute, continuous: Pin turns about z
  return MobilizedBody::Pin(parent, Transform(X_PJ.R() * R_a, X_PJ.p()), body,
                            Transform(R_a, Vec3(0)));
}

}  // namespace

namespace {

// The rigid bodies of a URDF tree: each link's head (the link on the movable joint above it, or
// the root) and its frame in the head's, composed along fixed joints; each head's merged mass.
struct RigidBodies {
  std::map<std::string, std::string> head;
  std::map<std::string, LinkMass> mass;  // by head
};

RigidBodies rigid_bodies(
    const std::string& root, const std::map<std::string, const tinyxml2::XMLElement*>& links,
    const std::map<std::string, std::vector<const tinyxml2::XMLElement*>>& children) {
  RigidBodies out;
  std::map<std::string, Transform> X_H;  // link frame in its head's
  std::vector<std::string> todo{root};
  out.head[root] = root;
  X_H[root] = Transform();
  while (!todo.empty()) {
    const std::string link = todo.back();
    todo.pop_back();
    const auto below = children.find(link);
    if (below == children.end()) continue;
    for (const tinyxml2::XMLElement* j : below->second) {
      const std::string child = j->FirstChildElement("child")->Attribute("link");
      const bool welded = std::string(j->Attribute("type")) == "fixed";
      out.head[child] = welded ? out.head[link] : child;
      X_H[child] = welded ? X_H[link] * origin(j) : Transform();
      todo.push_back(child);
    }
  }
  for (const auto& [link, head] : out.head) {
    const auto l = links.find(link);
    LinkMass lm = link_mass(l == links.end() ? nullptr : l->second);
    const Transform& X = X_H.at(link);
    lm = {lm.m, X.R() * lm.Ic * ~X.R(), X * lm.c};
    out.mass[head] = welded_pair(out.mass[head], lm);
  }
  return out;
}

// The model's length scale for round-off: the largest joint or inertial offset, else 1 m.
double length_scale(const tinyxml2::XMLElement* robot) {
  double L = 0;
  for (auto* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint"))
    L = std::max(L, origin(j).p().norm());
  for (auto* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link"))
    if (const auto* in = l->FirstChildElement("inertial")) L = std::max(L, origin(in).p().norm());
  return L > 0 ? L : 1.0;
}

}  // namespace

UrdfTwin::UrdfTwin(const std::string& path, const ::Eigen::Vector3d& gravity, bool floating,
                   bool balance_inertia)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
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
  // The root: the link no joint has as child, or a parent "world" no link defines (the ground).
  std::string root = children.count("world") && !links.count("world") ? "world" : "";
  for (const auto& [name, l] : links)
    if (root.empty() && !joint_to_child.count(name)) root = name;
  const RigidBodies rigid = rigid_bodies(root, links, children);
  const double length = length_scale(robot);
  // A link's body: its rigid body's merged mass on the head, none on the links welded to it.
  const auto body_of = [&](const std::string& link) {
    if (rigid.head.at(link) != link) return Body::Rigid(MassProperties(0, Vec3(0), Inertia(0)));
    return Body::Rigid(simbody_mass(link, rigid.mass.at(link), length, balance_inertia));
  };
  // Build from the root outwards; a floating root carries its own <inertial>.
  MobilizedBody root_body = s.matter.updGround();
  if (floating) {
    root_body = MobilizedBody::Free(s.matter.updGround(), Transform(), body_of(root), Transform());
    s.joints.push_back({root, "floating", root_body});
  }
  const bool root_moves = floating;
  std::vector<std::pair<std::string, MobilizedBody>> todo{{root, root_body}};
  while (!todo.empty()) {
    auto [link, parent] = todo.back();
    todo.pop_back();
    for (const tinyxml2::XMLElement* j : children[link]) {
      const std::string name = j->Attribute("name"), type = j->Attribute("type");
      const std::string child = j->FirstChildElement("child")->Attribute("link");
      const Vec3 axis = triple(j->FirstChildElement("axis"), "xyz",
                               type == "planar" ? Vec3(0, 0, 1) : Vec3(1, 0, 0));
      // The links welded to a fixed base never move: their mass is not checked, nor needed.
      const bool never_moves = !root_moves && rigid.head.at(child) == root;
      const MobilizedBody mb = mobilize(
          parent, type, origin(j), axis,
          never_moves ? Body::Rigid(MassProperties(0, Vec3(0), Inertia(0))) : body_of(child));
      if (type != "fixed") s.joints.push_back({name, type, mb});
      if (type == "revolute" || type == "continuous" || type == "prismatic") {
        const double c = number(j->FirstChildElement("dynamics"), "damping", 0);
        if (c != 0) Force::MobilityLinearDamper(s.forces, mb, MobilizerUIndex(0), c);
        // Coulomb friction, regularised at femdyn's default v_s = 0.01 (URDF gives none).
        const double f = number(j->FirstChildElement("dynamics"), "friction", 0);
        if (f != 0)
          Force::Custom(s.forces,  // (Simbody takes ownership of the implementation)
                        new CoulombFriction(mb, f, 0.01));
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

UrdfTwinEquations UrdfTwin::equations(const std::vector<std::string>& rate_names,
                                      const std::vector<std::string>& configuration_names,
                                      const ::Eigen::VectorXd& q, const ::Eigen::VectorXd& qd) {
  Impl& s = *impl_;
  const int n = static_cast<int>(rate_names.size()), nu = s.state.getNU();
  std::map<std::string, int> rate, entry;  // a name -> its index in v, in q
  for (int a = 0; a < n; ++a) rate[rate_names[a]] = a;
  for (int i = 0; i < static_cast<int>(configuration_names.size()); ++i)
    entry[configuration_names[i]] = i;
  const auto at = [](const std::map<std::string, int>& index, const std::string& name) {
    const auto it = index.find(name);
    if (it == index.end()) throw femdyn::Error("the URDF twin finds no coordinate '" + name + "'");
    return it->second;
  };
  // u = C v + Ċ-free part and Simbody's q from femdyn's: a coordinate drives its joint, a mimic
  // joint follows its leader, a planar joint's (x, y, θ) is Simbody's (θ, x, y), and a floating
  // joint's (v, ω) in its child's axes is Simbody's u = (R ω, R v) in the parent's (F) axes, so
  // u̇ = C v̇ + Ċ v with Ċ v = R (ω × v) on the linear part (R ω has no such term).
  ::Eigen::MatrixXd C = ::Eigen::MatrixXd::Zero(nu, n);
  ::Eigen::VectorXd Cdot_v = ::Eigen::VectorXd::Zero(nu);
  Vector& sq = s.state.updQ();
  std::function<void(const std::string&, ::Eigen::RowVectorXd&, double&)> resolve =
      [&](const std::string& joint, ::Eigen::RowVectorXd& row, double& theta) {
        if (rate.count(joint)) {
          row = ::Eigen::RowVectorXd::Unit(n, rate.at(joint));
          theta = q[at(entry, joint)];
          return;
        }
        const auto m = s.mimic.find(joint);
        if (m == s.mimic.end())
          throw femdyn::Error("the URDF twin finds no coordinate '" + joint + "'");
        resolve(m->second.leader, row, theta);
        row *= m->second.k;
        theta = m->second.k * theta + m->second.offset;
      };
  for (const Impl::Joint& j : s.joints) {
    const int u0 = j.body.getFirstUIndex(s.state), q0 = j.body.getFirstQIndex(s.state);
    if (j.type == "floating") {
      const auto rates = [&](const char* first) { return at(rate, j.name + "." + first); };
      const int x = at(entry, j.name + ".x"), w = at(entry, j.name + ".qw");
      const ::Eigen::Matrix3d R =
          ::Eigen::Quaterniond(q[w], q[w + 1], q[w + 2], q[w + 3]).normalized().toRotationMatrix();
      for (int k = 0; k < 4; ++k) sq[q0 + k] = q[w + k];  // Simbody: (quaternion, p)
      for (int k = 0; k < 3; ++k) sq[q0 + 4 + k] = q[x + k];
      const int v = rates("vx"), om = rates("wx");
      C.block<3, 3>(u0, om) = R;
      C.block<3, 3>(u0 + 3, v) = R;
      Cdot_v.segment<3>(u0 + 3) = R * qd.segment<3>(om).cross(qd.segment<3>(v));
    } else if (j.type == "spherical") {
      // PyBullet's spherical joint: femdyn's ω in the child's axes is Simbody's Ball u = R ω in
      // the joint frame's; u̇ = R ω̇ + R (ω × ω) has no Ċ v term.
      const int w = at(entry, j.name + ".qw"), om = at(rate, j.name + ".wx");
      const ::Eigen::Matrix3d R =
          ::Eigen::Quaterniond(q[w], q[w + 1], q[w + 2], q[w + 3]).normalized().toRotationMatrix();
      for (int k = 0; k < 4; ++k) sq[q0 + k] = q[w + k];
      C.block<3, 3>(u0, om) = R;
    } else if (j.type == "planar") {
      const char* kOrder[] = {"theta", "x", "y"};  // Simbody's Planar: (θ, x, y)
      for (int k = 0; k < 3; ++k) {
        const std::string name = j.name + "." + kOrder[k];
        C(u0 + k, at(rate, name)) = 1;
        sq[q0 + k] = q[at(entry, name)];
      }
    } else {  // Pin, Slider: one q, one u
      ::Eigen::RowVectorXd row;
      double theta = 0;
      resolve(j.name, row, theta);
      C.row(u0) = row;
      sq[q0] = theta;
    }
  }
  {
    const ::Eigen::VectorXd u = C * qd;
    for (int a = 0; a < nu; ++a) s.state.updU()[a] = u[a];
  }
  return s.reduced_equations(C, Cdot_v);
}

}  // namespace femdyn::validation
