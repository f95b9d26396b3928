// MujocoPeer (validation/mujoco_peer.hpp): the one file that includes MuJoCo.
#include "validation/mujoco_peer.hpp"

#include <mujoco/mujoco.h>
#include <tinyxml2.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <stdexcept>

namespace femdyn::validation {

namespace {

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
struct VfsFiles {  // frees the files a VFS holds (mj_deleteVFS), not the VFS itself
  mjVFS* vfs;
  ~VfsFiles() { mj_deleteVFS(vfs); }
};

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// URDF's rpy: R = Rz(y) Ry(p) Rx(r).
Eigen::Matrix3d rpy_rotation(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d rotation_rpy(const Eigen::Matrix3d& R) {
  const double c = std::hypot(R(0, 0), R(1, 0));
  if (c > 1e-9)
    return {std::atan2(R(2, 1), R(2, 2)), std::atan2(-R(2, 0), c), std::atan2(R(1, 0), R(0, 0))};
  return {std::atan2(-R(1, 2), R(1, 1)), std::atan2(-R(2, 0), c), 0.0};
}

std::string numbers(std::initializer_list<double> values) {
  std::string out;
  char buffer[32];
  for (double v : values) {
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    out += (out.empty() ? "" : " ") + std::string(buffer);
  }
  return out;
}

// MuJoCo's compiler turns a full inertia tensor into principal axes by an iteration that stops
// early: on HyQ's upper leg it returns ixy −0.0030199710 for −0.00302, and M^s is off by 1e-7.
// So each <inertial> is rewritten in its principal axes first (Eigen's symmetric eigensolver,
// exact to round-off; the axes ordered and signed to be nearest the given ones), which MuJoCo
// takes exactly. Left as written if its rpy would not reproduce the axes to 1e-14 (near the
// rpy's singularity) or the tensor is already diagonal.
void write_principal_axes(tinyxml2::XMLElement* inertial) {
  tinyxml2::XMLElement* tensor = inertial->FirstChildElement("inertia");
  if (!tensor) return;
  const auto get = [&](const char* name) { return tensor->DoubleAttribute(name, 0.0); };
  Eigen::Matrix3d I;
  I << get("ixx"), get("ixy"), get("ixz"), get("ixy"), get("iyy"), get("iyz"), get("ixz"),
      get("iyz"), get("izz");
  if (I(0, 1) == 0 && I(0, 2) == 0 && I(1, 2) == 0) return;
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  tinyxml2::XMLElement* origin = inertial->FirstChildElement("origin");
  if (origin && origin->Attribute("rpy")) {
    std::istringstream in(origin->Attribute("rpy"));
    if (!(in >> rpy[0] >> rpy[1] >> rpy[2])) return;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(I);
  if (eig.info() != Eigen::Success) return;
  // The column order nearest the identity, each column signed to a positive diagonal.
  std::array<int, 3> order{0, 1, 2}, best = order;
  double best_score = -1;
  do {
    double score = 1;
    for (int k = 0; k < 3; ++k) score *= std::abs(eig.eigenvectors()(k, order[k]));
    if (score > best_score) {
      best_score = score;
      best = order;
    }
  } while (std::next_permutation(order.begin(), order.end()));
  Eigen::Matrix3d V;
  Eigen::Vector3d d;
  for (int k = 0; k < 3; ++k) {
    V.col(k) = eig.eigenvectors().col(best[k]);
    if (V(k, k) < 0) V.col(k) = -V.col(k);
    d[k] = eig.eigenvalues()[best[k]];
  }
  if (V.determinant() < 0) V.col(2) = -V.col(2);
  const Eigen::Matrix3d R = rpy_rotation(rpy) * V;
  const Eigen::Vector3d principal = rotation_rpy(R);
  if ((rpy_rotation(principal) - R).cwiseAbs().maxCoeff() > 1e-14) return;
  if (!origin) origin = inertial->InsertNewChildElement("origin");
  origin->SetAttribute("rpy", numbers({principal[0], principal[1], principal[2]}).c_str());
  tensor->SetAttribute("ixx", numbers({d[0]}).c_str());
  tensor->SetAttribute("iyy", numbers({d[1]}).c_str());
  tensor->SetAttribute("izz", numbers({d[2]}).c_str());
  for (const char* name : {"ixy", "ixz", "iyz"}) tensor->SetAttribute(name, "0");
}

// The URDF text MuJoCo is given (see the header): inertias as written, no geometry, and with
// `floating` a free joint above the root link.
std::string prepared_urdf(const std::string& path, bool floating) {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLError status = doc.LoadFile(path.c_str());
  if (status == tinyxml2::XML_ERROR_FILE_NOT_FOUND ||
      status == tinyxml2::XML_ERROR_FILE_COULD_NOT_BE_OPENED)
    throw std::runtime_error(path + ": MuJoCo peer: cannot open file");
  if (status != tinyxml2::XML_SUCCESS)
    throw std::runtime_error(path + ": MuJoCo peer: malformed XML at line " +
                             std::to_string(doc.ErrorLineNum()) + " (" + doc.ErrorName() + ")");
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw std::runtime_error(path + ": MuJoCo peer: no <robot> element");
  std::set<std::string> links, children, joints;
  for (tinyxml2::XMLElement* link = robot->FirstChildElement("link"); link;
       link = link->NextSiblingElement("link")) {
    if (const char* name = link->Attribute("name")) links.insert(name);
    for (const char* geometry : {"visual", "collision"})
      while (tinyxml2::XMLElement* g = link->FirstChildElement(geometry)) link->DeleteChild(g);
    if (tinyxml2::XMLElement* inertial = link->FirstChildElement("inertial"))
      write_principal_axes(inertial);
  }
  for (tinyxml2::XMLElement* joint = robot->FirstChildElement("joint"); joint;
       joint = joint->NextSiblingElement("joint")) {
    if (const char* name = joint->Attribute("name")) joints.insert(name);
    if (const tinyxml2::XMLElement* child = joint->FirstChildElement("child"))
      if (const char* name = child->Attribute("link")) children.insert(name);
  }
  std::vector<std::string> roots;
  for (const std::string& l : links)
    if (!children.count(l)) roots.push_back(l);
  const auto refuse = [&](const std::string& why) {
    throw std::runtime_error(path + ": MuJoCo peer: " + why);
  };
  if (roots.size() != 1) refuse("one root link expected, not " + std::to_string(roots.size()));
  const std::string& root = roots[0];
  if (links.count("world") && root != "world") refuse("a link other than the root is 'world'");
  if (floating && root == "world") refuse("the root link is the world: no floating base");
  while (tinyxml2::XMLElement* old = robot->FirstChildElement("mujoco")) robot->DeleteChild(old);

  // No fusing (fusestatic="false"): MuJoCo would diagonalise a fused inertia again, roughly.
  tinyxml2::XMLElement* extension = doc.NewElement("mujoco");
  tinyxml2::XMLElement* compiler = extension->InsertNewChildElement("compiler");
  compiler->SetAttribute("fusestatic", "false");
  compiler->SetAttribute("discardvisual", "true");
  compiler->SetAttribute("inertiafromgeom", "false");
  compiler->SetAttribute("balanceinertia", "false");
  compiler->SetAttribute("boundmass", "0");
  compiler->SetAttribute("boundinertia", "0");
  robot->InsertFirstChild(extension);

  // MuJoCo's importer makes a root link named "world" its world body. Welded, the root link is
  // renamed so (its inertia never moves); floating, a link "world" is added above it, joined by
  // a URDF "floating" joint, which MuJoCo makes a free joint.
  if (floating) {
    std::string name = "mujoco_peer_free";
    while (joints.count(name)) name += "_";
    tinyxml2::XMLElement* link = doc.NewElement("link");
    link->SetAttribute("name", "world");
    robot->InsertAfterChild(extension, link);
    tinyxml2::XMLElement* joint = doc.NewElement("joint");
    joint->SetAttribute("name", name.c_str());
    joint->SetAttribute("type", "floating");
    joint->InsertNewChildElement("parent")->SetAttribute("link", "world");
    joint->InsertNewChildElement("child")->SetAttribute("link", root.c_str());
    robot->InsertAfterChild(link, joint);
  } else if (root != "world") {
    for (tinyxml2::XMLElement* link = robot->FirstChildElement("link"); link;
         link = link->NextSiblingElement("link"))
      if (link->Attribute("name", root.c_str())) link->SetAttribute("name", "world");
    for (tinyxml2::XMLElement* joint = robot->FirstChildElement("joint"); joint;
         joint = joint->NextSiblingElement("joint"))
      if (tinyxml2::XMLElement* parent = joint->FirstChildElement("parent"))
        if (parent->Attribute("link", root.c_str())) parent->SetAttribute("link", "world");
  }
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

}  // namespace

struct MujocoPeer::Impl {
  std::unique_ptr<mjModel, ModelDeleter> m;
  std::unique_ptr<mjData, DataDeleter> d;
  int n = 0, nq = 0;  // femdyn's rates and coordinates
  // Each femdyn joint that moves: its rates (1, 3 for a ball, 6 for a free joint), its MuJoCo
  // qpos and dof addresses, and its femdyn q and v offsets.
  struct Map {
    int rates, q, v, fq, fv;
  };
  std::vector<Map> joints;
  Eigen::MatrixXd M;  // mj_fullM's output (nv × nv, symmetric)

  // qvel = P v (mujoco_peer.hpp).
  Eigen::MatrixXd P(const Eigen::VectorXd& q) const {
    Eigen::MatrixXd p = Eigen::MatrixXd::Zero(n, n);
    for (const Map& j : joints) {
      if (j.rates == 1) p(j.v, j.fv) = 1;
      if (j.rates == 3) p.block<3, 3>(j.v, j.fv).setIdentity();
      if (j.rates == 6) {
        p.block<3, 3>(j.v, j.fv) = rotation(q, j.fq + 3);
        p.block<3, 3>(j.v + 3, j.fv + 3).setIdentity();
      }
    }
    return p;
  }
  static Eigen::Matrix3d rotation(const Eigen::VectorXd& q, int at) {
    return Eigen::Quaterniond(q[at], q[at + 1], q[at + 2], q[at + 3])
        .normalized()
        .toRotationMatrix();
  }
  // Ṗ v (nonzero on a free joint's linear triple only).
  Eigen::VectorXd Pdot_v(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
    for (const Map& j : joints)
      if (j.rates == 6)
        c.segment<3>(j.v) =
            rotation(q, j.fq + 3) *
            Eigen::Vector3d(v.segment<3>(j.fv + 3)).cross(Eigen::Vector3d(v.segment<3>(j.fv)));
    return c;
  }
  Eigen::VectorXd to_qpos(const Eigen::VectorXd& q) const {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(m->nq);
    for (const Map& j : joints) {
      const int width = j.rates == 1 ? 1 : j.rates == 3 ? 4 : 7;
      out.segment(j.q, width) = q.segment(j.fq, width);
    }
    return out;
  }
  void check_sizes(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
    if (q.size() != nq || v.size() != n)
      throw std::invalid_argument("MujocoPeer: q or v of the wrong size");
  }
  void load_state(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    mj_resetData(m.get(), d.get());
    const Eigen::VectorXd pos = to_qpos(q), vel = P(q) * qd;
    mju_copy(d->qpos, pos.data(), m->nq);
    mju_copy(d->qvel, vel.data(), m->nv);
  }
};

namespace {

// MuJoCo's compile of `text` (as the file `file`, from a virtual file system).
mjModel* compiled(const std::string& text, const std::string& file, const std::string& source) {
  const auto vfs = std::make_unique<mjVFS>();  // (about 2 MB: not on the stack)
  mj_defaultVFS(vfs.get());
  const VfsFiles files{vfs.get()};
  if (mj_makeEmptyFileVFS(vfs.get(), file.c_str(), static_cast<int>(text.size())) != 0)
    throw std::runtime_error(source + ": MuJoCo peer: the virtual file system refused it");
  std::copy(text.begin(), text.end(),
            static_cast<char*>(vfs->filedata[mj_findFileVFS(vfs.get(), file.c_str())]));
  char error[1000] = "";
  mjModel* m = mj_loadXML(file.c_str(), vfs.get(), error, sizeof error);
  if (!m) throw std::runtime_error(source + ": MuJoCo: " + one_line(error));
  return m;
}

// The MJCF text MuJoCo is given (see the header): <include>s expanded (relative to the main
// file's folder), then mesh and height-field geoms, <asset>, <contact> and every reference to an
// asset removed, and what M, τ and q̈ do not depend on and MuJoCo 2.2 may not know: actuators,
// sensors, tendons, keyframes, <option>'s integrator and flags, joints' actuator force ranges.
// (Gravity compensation, which does change τ, is reported by the reader.)
// The <mesh> assets whose files exist (their paths made absolute: the prepared text is compiled
// from elsewhere) and the geoms that use them are marked femdyn-kept; the others go with the
// assets. MuJoCo 2.2 takes a mesh's mass from its equivalent-inertia box unless exactmeshinertia,
// where MuJoCo 3 and femdyn take the solid's volume: the peer compiles with exactmeshinertia.
void keep_meshes(tinyxml2::XMLElement& root, const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(path).parent_path();
  fs::path meshdir = folder;
  tinyxml2::XMLElement* compiler = root.FirstChildElement("compiler");
  if (!compiler)
    compiler = root.InsertFirstChild(root.GetDocument()->NewElement("compiler"))->ToElement();
  for (const char* dir : {"assetdir", "meshdir"})
    if (const char* d = compiler->Attribute(dir))
      meshdir = fs::path(d).is_absolute() ? fs::path(d) : folder / d;
  compiler->SetAttribute("exactmeshinertia", "true");
  // MuJoCo 3's default, which femdyn's reader follows: a range without `limited` is a limit
  // (MuJoCo 2.2 refuses it otherwise; limits are constraints, off in the peer).
  if (!compiler->Attribute("autolimits")) compiler->SetAttribute("autolimits", "true");
  std::set<std::string> kept;
  std::vector<tinyxml2::XMLElement*> stack = {&root};
  while (!stack.empty()) {
    tinyxml2::XMLElement* e = stack.back();
    stack.pop_back();
    for (tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      stack.push_back(c);
      if (std::string(c->Name()) != "mesh" || std::string(e->Name()) != "asset") continue;
      const char* file = c->Attribute("file");
      const fs::path target =
          file ? (fs::path(file).is_absolute() ? fs::path(file) : meshdir / file) : fs::path();
      std::error_code ec;
      if (file && !fs::is_regular_file(target, ec)) continue;
      if (file) c->SetAttribute("file", target.string().c_str());
      c->SetAttribute("femdyn-kept", true);
      kept.insert(c->Attribute("name") ? c->Attribute("name")
                                       : fs::path(file ? file : "").stem().string());
    }
  }
  stack = {&root};
  while (!stack.empty()) {
    tinyxml2::XMLElement* e = stack.back();
    stack.pop_back();
    for (tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      stack.push_back(c);
      if (std::string(c->Name()) == "geom" && c->Attribute("mesh") &&
          kept.count(c->Attribute("mesh")))
        c->SetAttribute("femdyn-kept", true);
    }
  }
}

std::string prepared_mjcf(const std::string& path) {
  tinyxml2::XMLDocument doc;
  const auto refuse = [&](const std::string& why) {
    throw std::runtime_error(path + ": MuJoCo peer: " + why);
  };
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS) refuse("cannot read it as XML");
  tinyxml2::XMLElement* root = doc.FirstChildElement("mujoco");
  if (!root) refuse("no <mujoco> element");
  const std::string folder = std::filesystem::path(path).parent_path().string();
  for (int round = 0;; ++round) {
    std::vector<tinyxml2::XMLElement*> includes, stack = {root};
    while (!stack.empty()) {
      tinyxml2::XMLElement* e = stack.back();
      stack.pop_back();
      for (tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement())
        (std::string(c->Name()) == "include" ? includes : stack).push_back(c);
    }
    if (includes.empty()) break;
    if (round > 64) refuse("<include>s nested too deep");
    for (tinyxml2::XMLElement* inc : includes) {
      tinyxml2::XMLDocument part;
      const char* file = inc->Attribute("file");
      const std::string target = file ? folder + "/" + file : "";
      if (!file || part.LoadFile(target.c_str()) != tinyxml2::XML_SUCCESS ||
          !part.FirstChildElement("mujoco"))
        refuse("cannot include " + target);
      tinyxml2::XMLNode* after = inc;  // the included children in file order, in its place
      for (const tinyxml2::XMLElement* c = part.FirstChildElement("mujoco")->FirstChildElement(); c;
           c = c->NextSiblingElement())
        after = inc->Parent()->InsertAfterChild(after, c->DeepClone(&doc));
      inc->Parent()->DeleteChild(inc);
    }
  }
  keep_meshes(*root, path);
  std::vector<tinyxml2::XMLElement*> stack = {root}, doomed;
  while (!stack.empty()) {
    tinyxml2::XMLElement* e = stack.back();
    stack.pop_back();
    for (const char* a :
         {"material", "texture", "hfield", "meshdir", "assetdir", "texturedir", "integrator",
          "actuatorfrcrange", "actuatorfrclimited", "actuatorforcerange", "actuatorforcelimited",
          "actuatorgravcomp", "gravcomp"})
      e->DeleteAttribute(a);
    for (tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
      const std::string tag = c->Name();
      const char* type = c->Attribute("type");
      const bool mesh_geom =
          tag == "geom" && ((c->Attribute("mesh") && !c->BoolAttribute("femdyn-kept")) ||
                            (type && std::string(type) == "hfield"));
      c->DeleteAttribute("femdyn-kept");
      if (tag == "asset") {  // only the meshes keep_meshes kept
        for (tinyxml2::XMLElement* a = c->FirstChildElement(); a; a = a->NextSiblingElement())
          if (!a->BoolAttribute("femdyn-kept")) doomed.push_back(a);
        for (tinyxml2::XMLElement* a = c->FirstChildElement(); a; a = a->NextSiblingElement())
          a->DeleteAttribute("femdyn-kept");
        continue;
      }
      // An actuator's defaults go with the actuators (MuJoCo 3's kv or inheritrange on them stop
      // MuJoCo 2.2 reading the file).
      const bool actuator_default = std::string(e->Name()) == "default" &&
                                    (tag == "general" || tag == "motor" || tag == "position" ||
                                     tag == "velocity" || tag == "intvelocity" || tag == "damper" ||
                                     tag == "cylinder" || tag == "muscle" || tag == "adhesion");
      const bool unused = tag == "contact" || tag == "skin" || tag == "flag" || tag == "actuator" ||
                          tag == "sensor" || tag == "keyframe" || tag == "tendon" ||
                          actuator_default;
      (unused || mesh_geom ? doomed : stack).push_back(c);
    }
  }
  for (tinyxml2::XMLElement* e : doomed) e->Parent()->DeleteChild(e);
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

}  // namespace

MujocoPeer::MujocoPeer(const std::string& mjcf_path, const Eigen::Vector3d& gravity,
                       const std::vector<MjcfJoint>& joints)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.m.reset(compiled(prepared_mjcf(mjcf_path), "mujoco_peer.xml", mjcf_path));
  mjModel& m = *s.m;
  for (int k = 0; k < 3; ++k) m.opt.gravity[k] = gravity[k], m.opt.wind[k] = 0;
  m.opt.density = m.opt.viscosity = 0;  // fluid forces: reported by the reader, not modelled
  m.opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_CONTACT;
  // What the reader reports leaving out, left out here too: springs on ball and free joints
  // (femdyn's joint springs act on one coordinate; their dampers are read).
  for (int j = 0; j < m.njnt; ++j)
    if (m.jnt_type[j] == mjJNT_BALL || m.jnt_type[j] == mjJNT_FREE) m.jnt_stiffness[j] = 0;
  const auto refuse = [&](const std::string& why) {
    throw std::runtime_error(mjcf_path + ": MuJoCo peer: " + why);
  };
  for (const MjcfJoint& j : joints) {
    int id = mj_name2id(&m, mjOBJ_JOINT, j.name.c_str());
    if (id < 0 && j.name.rfind("joint", 0) == 0 &&
        j.name.find_first_not_of("0123456789", 5) == std::string::npos && j.name.size() > 5) {
      id = std::stoi(j.name.substr(5));
      if (id >= m.njnt || mj_id2name(&m, mjOBJ_JOINT, id)) id = -1;
    }
    const int want = j.rates == 1 ? -1 : j.rates == 3 ? mjJNT_BALL : mjJNT_FREE;
    if (id < 0 || (want < 0 ? m.jnt_type[id] != mjJNT_HINGE && m.jnt_type[id] != mjJNT_SLIDE
                            : m.jnt_type[id] != want))
      refuse("no joint '" + j.name + "' of " + std::to_string(j.rates) + " rates");
    s.joints.push_back({j.rates, m.jnt_qposadr[id], m.jnt_dofadr[id], s.nq, s.n});
    s.nq += j.rates == 1 ? 1 : j.rates + 1;
    s.n += j.rates;
  }
  if (m.nv != s.n)
    refuse("MuJoCo has " + std::to_string(m.nv) + " dofs, femdyn " + std::to_string(s.n) +
           " rates (an equality femdyn holds as a coupling?)");
  s.d.reset(mj_makeData(&m));
  if (!s.d) refuse("mj_makeData failed");
  s.M.resize(m.nv, m.nv);
}

MujocoPeer::MujocoPeer(const std::string& urdf_path, const Eigen::Vector3d& gravity, bool floating,
                       const std::vector<std::string>& coordinates, const Eigen::VectorXd& armature)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.m.reset(compiled(prepared_urdf(urdf_path, floating), "mujoco_peer.urdf", urdf_path));
  mjModel& m = *s.m;
  m.opt.gravity[0] = gravity[0];
  m.opt.gravity[1] = gravity[1];
  m.opt.gravity[2] = gravity[2];
  m.opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_CONTACT;
  std::fill(m.dof_armature, m.dof_armature + m.nv, 0.0);

  s.n = static_cast<int>(coordinates.size());
  s.nq = s.n + (floating ? 1 : 0);
  const auto refuse = [&](const std::string& why) {
    throw std::runtime_error(urdf_path + ": MuJoCo peer: " + why);
  };
  if (m.nv != s.n)
    refuse("MuJoCo has " + std::to_string(m.nv) + " dofs, femdyn " + std::to_string(s.n) +
           " coordinates" + (m.nv > s.n ? " (a <mimic> joint?)" : ""));
  const int base = floating ? 6 : 0;
  bool found_free = false;
  for (int j = 0; j < m.njnt; ++j) {
    if (m.jnt_type[j] == mjJNT_FREE && floating && !found_free) {
      found_free = true;
      s.joints.push_back({6, m.jnt_qposadr[j], m.jnt_dofadr[j], 0, 0});
      continue;
    }
    if (m.jnt_type[j] != mjJNT_HINGE && m.jnt_type[j] != mjJNT_SLIDE)
      refuse(std::string("joint '") + mj_id2name(&m, mjOBJ_JOINT, j) +
             "' is a ball or free joint inside the robot");
  }
  if (floating && !found_free) refuse("MuJoCo made no free joint of the root link");
  for (int k = base; k < s.n; ++k) {
    const int j = mj_name2id(&m, mjOBJ_JOINT, coordinates[k].c_str());
    if (j < 0 || (m.jnt_type[j] != mjJNT_HINGE && m.jnt_type[j] != mjJNT_SLIDE))
      refuse("no hinge or slide joint named '" + coordinates[k] + "'");
    s.joints.push_back({1, m.jnt_qposadr[j], m.jnt_dofadr[j], k + (floating ? 1 : 0), k});
    if (armature.size() == s.n) m.dof_armature[m.jnt_dofadr[j]] = armature[k];  // I_a G²
  }
  s.d.reset(mj_makeData(&m));
  if (!s.d) refuse("mj_makeData failed");
  s.M.resize(m.nv, m.nv);
}

MujocoPeer::~MujocoPeer() = default;

Eigen::MatrixXd MujocoPeer::mass(const Eigen::VectorXd& q) {
  Impl& s = *impl_;
  s.check_sizes(q, Eigen::VectorXd::Zero(s.n));
  s.load_state(q, Eigen::VectorXd::Zero(s.n));
  mj_kinematics(s.m.get(), s.d.get());
  mj_comPos(s.m.get(), s.d.get());
  mj_crb(s.m.get(), s.d.get());
  Eigen::MatrixXd M(s.n, s.n);
  mj_fullM(s.m.get(), M.data(), s.d->qM);  // symmetric: row- or column-major alike
  const Eigen::MatrixXd P = s.P(q);
  return P.transpose() * M * P;
}

Eigen::VectorXd MujocoPeer::inverse(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                    const Eigen::VectorXd& qdd) {
  Impl& s = *impl_;
  s.check_sizes(q, qd);
  s.load_state(q, qd);
  const Eigen::MatrixXd P = s.P(q);
  const Eigen::VectorXd acc = P * qdd + s.Pdot_v(q, qd);
  mju_copy(s.d->qacc, acc.data(), s.n);
  mj_inverse(s.m.get(), s.d.get());
  return P.transpose() * Eigen::Map<const Eigen::VectorXd>(s.d->qfrc_inverse, s.n);
}

Eigen::VectorXd MujocoPeer::forward(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                    const Eigen::VectorXd& tau) {
  Impl& s = *impl_;
  s.check_sizes(q, qd);
  s.load_state(q, qd);
  const Eigen::MatrixXd P = s.P(q);
  const Eigen::VectorXd force = P * tau;
  mju_copy(s.d->qfrc_applied, force.data(), s.n);
  mj_forward(s.m.get(), s.d.get());
  return P.transpose() * (Eigen::Map<const Eigen::VectorXd>(s.d->qacc, s.n) - s.Pdot_v(q, qd));
}

MujocoPeer::State MujocoPeer::state(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                    const Eigen::VectorXd& tau, const Eigen::VectorXd& qdd) const {
  const Impl& s = *impl_;
  s.check_sizes(q, qd);
  const Eigen::MatrixXd P = s.P(q);
  return {s.to_qpos(q), P * qd, P * qdd + s.Pdot_v(q, qd), P * tau};
}

void MujocoPeer::time_mass(const State& state) {
  const mjModel* m = impl_->m.get();
  mjData* d = impl_->d.get();
  mju_copy(d->qpos, state.qpos.data(), m->nq);
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_crb(m, d);
  mj_fullM(m, impl_->M.data(), d->qM);
}

void MujocoPeer::time_inverse(const State& state) {
  const mjModel* m = impl_->m.get();
  mjData* d = impl_->d.get();
  mju_copy(d->qpos, state.qpos.data(), m->nq);
  mju_copy(d->qvel, state.qvel.data(), m->nv);
  mju_copy(d->qacc, state.qacc.data(), m->nv);
  mj_inverse(m, d);
}

void MujocoPeer::time_forward(const State& state) {
  const mjModel* m = impl_->m.get();
  mjData* d = impl_->d.get();
  mju_copy(d->qpos, state.qpos.data(), m->nq);
  mju_copy(d->qvel, state.qvel.data(), m->nv);
  mju_copy(d->qfrc_applied, state.qfrc.data(), m->nv);
  mj_forward(m, d);
}

}  // namespace femdyn::validation
