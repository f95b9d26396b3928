#include "io/output.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <system_error>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "io/atomic_file.hpp"

namespace femdyn {

Json vector_json(const VecX& v) {
  Json a = Json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v[i]);
  return a;
}

Json matrix_json(const MatX& m) {
  Json a = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) a.push_back(vector_json(m.row(r).transpose()));
  return a;
}

namespace {

std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "% .10e", x);
  return buf;
}

void print_vec(std::ostringstream& out, const char* name, const VecX& v) {
  out << name << " =";
  for (Eigen::Index i = 0; i < v.size(); ++i) out << " " << num(v[i]);
  out << "\n";
}

void print_mat(std::ostringstream& out, const MatX& m) {
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    out << "  ";
    for (Eigen::Index c = 0; c < m.cols(); ++c) out << " " << num(m(r, c));
    out << "\n";
  }
}

}  // namespace

std::string json_text(const Json& doc) {
  const std::string raw = doc.dump(2, ' ', false, Json::error_handler_t::replace);
  std::string out;
  out.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const auto c = static_cast<unsigned char>(raw[i]);
    const auto next = i + 1 < raw.size() ? static_cast<unsigned char>(raw[i + 1]) : 0;
    if (c == 0x7f) {
      out += "\\u007f";
    } else if (c == 0xc2 && next >= 0x80 && next <= 0x9f) {  // C1: only inside strings
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(next));
      out += buf;
      ++i;
    } else {
      out += raw[i];
    }
  }
  return out;
}

Json routes_json(const Model& model) {
  Json j = Json::object();
  for (const auto& [key, name] : route_report(model).fields()) j[key] = name;
  return j;
}

Json equations_json(const Model& model, const Workspace& ws, const VecX& q, const VecX& qd,
                    const VecX& tau, const Status& dynamics, const LoopWorkspace* loops,
                    const std::vector<MatX>& D) {
  Json j;
  j["n"] = model.n();
  j["coordinates"] = model.coordinate_names;
  j["q"] = vector_json(q);
  j["qd"] = vector_json(qd);
  j["tau"] = vector_json(tau);
  j["M"] = matrix_json(ws.Ms);
  j["h"] = vector_json(ws.h);
  j["Q"] = vector_json(ws.Q);
  j["qdd"] = dynamics.ok ? vector_json(ws.qdd) : Json();
  if (!dynamics.ok) j["failure"] = dynamics.message;
  j["routes"] = routes_json(model);
  if (loops && dynamics.ok) {
    j["lambda"] = vector_json(loops->lambda);
    j["constraint_forces"] = vector_json(loops->k.J.transpose() * loops->lambda);
  }
  if (!D.empty()) {
    Json d = Json::array();
    for (const MatX& Da : D) d.push_back(matrix_json(Da));
    j["D"] = d;
  }
  return j;
}

std::string equations_text(const Model& model, const Workspace& ws, const VecX& q, const VecX& qd,
                           const VecX& tau, const Status& dynamics, const LoopWorkspace* loops,
                           const std::vector<MatX>& D) {
  std::ostringstream out;
  out << "model: " << model.name << "\n";
  out << "coordinates:";
  for (const auto& c : model.coordinate_names) out << " " << c;
  out << "\n";
  print_vec(out, "q  ", q);
  print_vec(out, "qd ", qd);
  print_vec(out, "tau", tau);
  out << "M^s (mass matrix):\n";
  print_mat(out, ws.Ms);
  print_vec(out, "h  ", ws.h);
  print_vec(out, "Q  ", ws.Q);
  if (loops)
    out << "closed loops (" << model.constraint_rows
        << " equations): qdd from M^s qdd + h = Q + Phi_q^T lambda, Phi_q qdd = -Phi_q' qd\n";
  if (!dynamics.ok) {
    out << "qdd = (none: " << dynamics.message << ")\n";
  } else {
    print_vec(out, "qdd", ws.qdd);
    if (loops) {
      print_vec(out, "lambda", loops->lambda);
      print_vec(out, "Phi_q^T lambda", VecX(loops->k.J.transpose() * loops->lambda));
    }
  }
  for (std::size_t a = 0; a < D.size(); ++a) {
    out << "D[" << a << "] (" << model.coordinate_names[a] << "):\n";
    print_mat(out, D[a]);
  }
  return out.str();
}

std::string correlation_table_text(const Model& model) {
  std::ostringstream out;
  out << "correlation table N_m (" << model.elements.size() << " elements x 6 per node; "
      << "per node: x y z rx ry rz; 0 = left out):\n";
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    const ElementEntry& E = model.elements[e];
    out << "  " << std::setw(3) << e + 1 << " " << std::left << std::setw(13)
        << E.element->type_name() << std::right << " [";
    for (std::size_t l = 0; l < E.table_row.size(); ++l)
      out << (l ? (l % 6 == 0 ? " | " : ", ") : "") << E.table_row[l];
    out << "]\n";
  }
  return out.str();
}

// A joint's own forces and limits (core/joints/passive.hpp), only those it has: for info.
Json joint_properties(const Joint& j) {
  Json p = Json::object();
  const auto bound = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
  if (std::isfinite(j.lower) || std::isfinite(j.upper))
    p["limits"] = {bound(j.lower), bound(j.upper)};
  if (j.stop) p["stop"] = {{"stiffness", j.stop_stiffness}, {"dissipation", j.stop_dissipation}};
  if (j.stiffness != 0) p["spring"] = {{"stiffness", j.stiffness}, {"rest", j.rest}};
  if (j.damping != 0) p["damping"] = j.damping;
  if (j.friction != 0) p["friction"] = {{"force", j.friction}, {"velocity", j.friction_velocity}};
  if (j.armature != 0)
    p["armature"] = {{"inertia", j.armature}, {"gear", j.gear}, {"reflected", j.reflected_inertia}};
  if (std::isfinite(j.effort_limit)) p["effort_limit"] = j.effort_limit;
  if (std::isfinite(j.velocity_limit)) p["velocity_limit"] = j.velocity_limit;
  if (!j.actuated) p["actuated"] = false;
  if (j.sample_range != 0) p["sample_range"] = j.sample_range;
  return p;
}

namespace {
// A driven joint's motion: "spin-up to rate 4 in 15 s …" or "q(t) = 0 + 0.5 t - …".
std::string prescribed_text(const PrescribedMotion& m) {
  if (m.kind == PrescribedMotion::Kind::SpinUp)
    return "spin-up to rate " + format_number(m.rate) + " in " + format_number(m.time) +
           " s (Simo & Vu-Quoc's profile), steady after";
  std::string s = "q(t) =";
  for (std::size_t k = 0; k < m.coefficients.size(); ++k) {
    const double c = m.coefficients[k];
    const std::string sign = k == 0 ? (c < 0 ? " -" : " ") : (c < 0 ? " - " : " + ");
    const std::string power = k == 0 ? "" : k == 1 ? " t" : " t^" + std::to_string(k);
    s += sign + format_number(std::abs(c)) + power;
  }
  return s;
}
}  // namespace

// The same on one line: "limits [-1, 0.5] with a stop (k 1e4, d 0.5); damping 2; …".
std::string joint_properties_text(const Joint& j) {
  std::vector<std::string> parts;
  const auto bound = [](double x) {
    return std::isfinite(x) ? format_number(x) : std::string(x < 0 ? "-inf" : "inf");
  };
  if (std::isfinite(j.lower) || std::isfinite(j.upper))
    parts.push_back("limits [" + bound(j.lower) + ", " + bound(j.upper) + "]" +
                    (j.stop ? " with a stop (k " + format_number(j.stop_stiffness) + ", d " +
                                  format_number(j.stop_dissipation) + ")"
                            : " reported"));
  if (j.stiffness != 0)
    parts.push_back("spring " + format_number(j.stiffness) + " at " + format_number(j.rest));
  if (j.damping != 0) parts.push_back("damping " + format_number(j.damping));
  if (j.friction != 0)
    parts.push_back("Coulomb friction " + format_number(j.friction) + " (v_s " +
                    format_number(j.friction_velocity) + ")");
  if (j.armature != 0)
    parts.push_back("rotor " + format_number(j.armature) + " x gear " + format_number(j.gear) +
                    "^2 = " + format_number(j.reflected_inertia));
  if (std::isfinite(j.effort_limit)) parts.push_back("effort " + format_number(j.effort_limit));
  if (std::isfinite(j.velocity_limit))
    parts.push_back("velocity " + format_number(j.velocity_limit));
  if (!j.actuated) parts.push_back("not actuated");
  if (j.sample_range != 0) parts.push_back("sampled within " + format_number(j.sample_range));
  std::string out;
  for (const std::string& part : parts) out += (out.empty() ? "" : "; ") + part;
  return out;
}

namespace {
// A constraint's or spring's end as the model file named it: "E_rod (on rod_FE)", a body or
// "world", or "triangle at [0.02 -0.018 0]" (a point on a body).
std::string place_name(const Model& model, const Attachment& A) {
  const std::string body = A.body < 0 ? std::string("world") : model.bodies[A.body].name;
  if (A.name != body) return A.name + " (on " + body + ")";
  if (A.p.isZero(0)) return body;
  std::ostringstream s;
  s << body << " at [" << A.p.transpose() << "]";
  return s.str();
}
}  // namespace

std::vector<std::string> actuated_names(const Model& model) {
  std::vector<std::string> names;
  for (int i : model.actuated) names.push_back(model.coordinate_names[i]);
  return names;
}

namespace {

// "theta = …": how a joint's coordinate follows q (a law, several rates, or a row of C).
void joint_relation(std::ostream& out, const Model& model, const Joint& j,
                    const CoupledJoint* law) {
  if (law) {  // θ = f(θ_followed…)
    out << "   theta = " << law->law->form() << " of";
    for (int s : law->sources) out << " " << model.bodies[model.theta_joint[s]].joint.name;
  } else if (j.nv > 1) {  // (never coupled)
    out << "   " << j.nq << " coordinates, " << j.nv << " rates";
  } else if (moves(j)) {
    out << "   theta =";
    bool first = true;
    for (SpRowMat::InnerIterator it(model.C_sparse, j.idx_v); it; ++it) {
      const double c = it.value();
      if (c == 0) continue;
      out << (first ? " " : " + ") << (c == 1 ? "" : num(c) + "*")
          << model.coordinate_names[it.col()];
      first = false;
    }
    if (model.theta0[j.idx_v] != 0) out << " + " << model.theta0[j.idx_v];
  }
}

void coordinates_text(std::ostream& out, const Model& model) {
  out << "coordinates (n = " << model.n() << "):";
  for (const auto& c : model.coordinate_names) out << " " << c;
  out << "\n";
  if (model.configuration_names != model.coordinate_names) {  // a spherical or free joint
    out << "configuration q (n_q = " << model.n_q() << "):";
    for (const auto& c : model.configuration_names) out << " " << c;
    out << "\n";
  }
  if (!model.fully_actuated()) {
    out << "actuated (n_a = " << model.n_actuated() << "):";
    for (const std::string& c : actuated_names(model)) out << " " << c;
    out << "\n";
  }
}

void joints_text(std::ostream& out, const Model& model) {
  // Joints counted as joints (a ball or free joint is one, of 3 or 6 rates θ̇).
  const auto movable = std::count_if(model.bodies.begin(), model.bodies.end(),
                                     [](const Body& b) { return moves(b.joint); });
  out << "joints (" << model.bodies.size() << ", " << movable << " movable, " << model.n_theta()
      << " joint rates):\n";
  std::vector<const CoupledJoint*> law_of(model.n_theta(), nullptr);  // θ -> its law, if any
  if (model.coupling_level)
    for (const CoupledJoint& c : model.coupling_level->coupled) law_of[c.theta] = &c;
  for (const Body& b : model.bodies) {
    const Joint& j = b.joint;
    const std::string_view type = joint_type_name(j.type);
    out << "  " << j.name << " (" << type << ") "
        << (b.parent < 0 ? std::string("world") : model.bodies[b.parent].name) << " -> " << b.name;
    joint_relation(out, model, j, j.idx_v >= 0 ? law_of[j.idx_v] : nullptr);
    out << "\n";
    if (const std::string p = joint_properties_text(j); !p.empty()) out << "      " << p << "\n";
    for (const PrescribedCoordinate& d : model.prescribed)
      if (d.joint == j.name) out << "      prescribed: " << prescribed_text(d.motion) << "\n";
  }
}

// Bodies with their elements, frames, and the loops and springs between places.
void bodies_text(std::ostream& out, const Model& model) {
  out << "bodies and elements (" << model.elements.size() << " elements):\n";
  std::vector<std::string> element_types(model.bodies.size());
  for (const ElementEntry& e : model.elements)
    element_types[e.body].append(" ").append(e.element->type_name());
  for (std::size_t b = 0; b < model.bodies.size(); ++b)
    out << "  " << model.bodies[b].name << ":" << element_types[b] << "\n";
  out << "frames (every body by its name, and " << model.frames.size() - model.bodies.size()
      << " named):\n";
  for (std::size_t f = model.bodies.size(); f < model.frames.size(); ++f) {
    const Frame& F = model.frames[f];
    out << "  " << F.name << " on " << model.bodies[F.body].name << " at [" << F.p_BF.transpose()
        << "]\n";
  }
  if (!model.constraints.empty()) {
    out << "constraints (" << model.constraint_rows << " equations; docs/loops.md):\n";
    for (const LoopConstraint& c : model.constraints) {
      out << "  " << c.name << ": " << constraint_type_name(c.type) << ", " << c.rows()
          << (c.rows() == 1 ? " equation" : " equations");
      if (c.type != ConstraintType::Gear)
        out << ", " << place_name(model, c.a) << " to " << place_name(model, c.b);
      out << "\n";
    }
  }
  if (!model.bars.empty()) {
    out << "flexible bars (docs/flexible.md):\n";
    for (const BarCentreline& bar : model.bars)
      out << "  " << bar.name << ": " << bar.stations.size() - 2 << " parts, from "
          << model.bodies[bar.stations.front()].name << " to "
          << model.bodies[bar.stations.back()].name << "\n";
  }
  if (!model.springs.empty()) {
    out << "springs:\n";
    for (const TwoPointSpring& s : model.springs)
      out << "  " << s.name << ": " << place_name(model, s.a) << " to " << place_name(model, s.b)
          << ", k " << s.stiffness << " N/m, rest " << s.rest_length << " m, c " << s.damping
          << " N s/m\n";
  }
}

// The node level: the transition coordinates kept and left out, and the table's approximations.
void node_level_text(std::ostream& out, const Model& model) {
  out << "transition coordinates u (N_u = " << model.n_u() << " kept):\n";
  for (int i = 0; i < model.n_u(); ++i)
    out << "  " << std::setw(3) << i + 1 << " " << model.dof_name(i) << "\n";
  out << "left out (" << model.left_out.size() << "):\n";
  for (const auto& s : model.left_out) out << "  " << s << "\n";
  out << (model.explicit_table ? "(table given in the model file)\n" : "");
  if (!model.approximations.empty()) {
    out << "approximations made by the table (" << model.approximations.size() << "):\n";
    for (const auto& s : model.approximations) out << "  " << s << "\n";
  }
}

}  // namespace

std::string info_text(const Model& model) {
  std::ostringstream out;
  out << "model: " << model.name << "\n";
  out << "gravity: [" << model.gravity.transpose() << "] m/s^2\n";
  coordinates_text(out, model);
  joints_text(out, model);
  bodies_text(out, model);
  node_level_text(out, model);
  out << "routes (which algorithm computes what; docs/design.md):\n";
  for (const auto& [key, name] : route_report(model).fields())
    out << "  " << key << ": " << name << "\n";
  out << correlation_table_text(model);
  return out.str();
}

Json info_json(const Model& model) {
  Json j;
  j["model"] = model.name;
  j["n"] = model.n();
  j["coordinates"] = model.coordinate_names;
  j["actuated"] = actuated_names(model);
  Json u = Json::array();
  for (int i = 0; i < model.n_u(); ++i) u.push_back(model.dof_name(i));
  j["transition_coordinates"] = u;
  j["left_out"] = model.left_out;
  j["approximations"] = model.approximations;
  j["routes"] = routes_json(model);
  Json table = Json::array();
  for (const ElementEntry& e : model.elements) table.push_back(e.table_row);
  j["correlation_table"] = table;
  Json elements = Json::array();
  for (const ElementEntry& e : model.elements)
    elements.push_back({{"type", std::string(e.element->type_name())},
                        {"body", model.bodies[e.body].name},
                        {"nodes", e.node_labels}});
  j["elements"] = elements;
  Json frames = Json::array();  // every frame: the bodies' own, then the named ones
  for (const Frame& F : model.frames)
    frames.push_back({{"name", F.name},
                      {"body", model.bodies[F.body].name},
                      {"xyz", vector_json(F.p_BF)},
                      {"R", matrix_json(F.R_BF)}});
  j["frames"] = frames;
  Json joints = Json::array();  // every joint, with its own forces and limits
  for (const Body& b : model.bodies) {
    Json joint = {{"name", b.joint.name},
                  {"type", std::string(joint_type_name(b.joint.type))},
                  {"parent", b.parent < 0 ? std::string("world") : model.bodies[b.parent].name},
                  {"body", b.name}};
    joint.update(joint_properties(b.joint));
    for (const PrescribedCoordinate& d : model.prescribed)
      if (d.joint == b.joint.name) joint["prescribed"] = prescribed_text(d.motion);
    joints.push_back(joint);
  }
  j["joints"] = joints;
  Json constraints = Json::array(), springs = Json::array();
  for (const LoopConstraint& c : model.constraints) {
    Json x = {{"name", c.name}, {"type", constraint_type_name(c.type)}, {"rows", c.rows()}};
    if (c.type != ConstraintType::Gear)
      x["a"] = place_name(model, c.a), x["b"] = place_name(model, c.b);
    constraints.push_back(x);
  }
  for (const TwoPointSpring& s : model.springs)
    springs.push_back({{"name", s.name},
                       {"a", place_name(model, s.a)},
                       {"b", place_name(model, s.b)},
                       {"stiffness", s.stiffness},
                       {"rest_length", s.rest_length},
                       {"damping", s.damping}});
  j["constraints"] = constraints;
  Json bars = Json::array();  // each flexible bar: its stations, clamp to tip
  for (const BarCentreline& bar : model.bars) {
    Json stations = Json::array();
    for (int s : bar.stations) stations.push_back(model.bodies[s].name);
    bars.push_back({{"name", bar.name},
                    {"parts", bar.stations.size() - 2},
                    {"stations", stations},
                    {"radius", bar.radius}});
  }
  j["bars"] = bars;
  j["springs"] = springs;
  return j;
}

void write_file_atomic(const std::string& path, const std::string& content, bool replace) {
  AtomicFile f(path, replace);
  f.stream() << content;
  f.commit();
}

namespace {

bool all_primitive(const Json& a) {
  return std::all_of(a.begin(), a.end(), [](const Json& x) { return x.is_primitive(); });
}

// One line: a vector, or a small matrix (e.g. a 3x3 inertia); a larger matrix gets a row a line.
bool is_flat(const Json& a) {
  if (all_primitive(a)) return true;
  for (const Json& x : a)
    if (!x.is_array() || !all_primitive(x)) return false;
  return a.dump().size() < 90;
}

int key_rank(const std::string& k) {
  static const char* order[] = {"$schema", "name", "description", "model", "gravity", "params",
                                "type", "parent", "joint", "origin", "xyz", "rpy", "axis", "limits",
                                "spring", "damping", "armature", "gear", "friction",
                                "friction_velocity", "effort_limit", "velocity_limit", "stop",
                                "actuated", "sample_range", "nodes", "elements", "mass", "com",
                                "inertia", "bodies", "couplings", "loads", "correlation_table",
                                // equations --json
                                "n", "coordinates", "q", "qd", "tau", "M", "h", "Q", "qdd", "D"};
  for (std::size_t i = 0; i < std::size(order); ++i)
    if (k == order[i]) return static_cast<int>(i);
  return static_cast<int>(std::size(order));
}

void write_json(std::ostringstream& o, const Json& j, int indent) {
  const std::string pad(indent + 2, ' ');
  if (j.is_object()) {
    std::vector<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
    std::stable_sort(keys.begin(), keys.end(),
                     [](const auto& a, const auto& b) { return key_rank(a) < key_rank(b); });
    if (keys.empty()) {
      o << "{}";
      return;
    }
    // A small object of vectors and numbers on one line: {"xyz": [..], "rpy": [..]}.
    bool small = true;
    for (const auto& k : keys)
      small = small && (j.at(k).is_primitive() || (j.at(k).is_array() && is_flat(j.at(k))));
    if (small && j.dump().size() < 72) {
      o << "{";
      for (std::size_t i = 0; i < keys.size(); ++i) {
        o << (i ? ", " : "") << Json(keys[i]).dump() << ": ";
        write_json(o, j.at(keys[i]), indent);
      }
      o << "}";
      return;
    }
    o << "{\n";
    for (std::size_t i = 0; i < keys.size(); ++i) {
      o << pad << Json(keys[i]).dump() << ": ";
      write_json(o, j.at(keys[i]), indent + 2);
      o << (i + 1 < keys.size() ? ",\n" : "\n");
    }
    o << std::string(indent, ' ') << "}";
  } else if (j.is_array() && !is_flat(j)) {
    o << "[\n";
    for (std::size_t i = 0; i < j.size(); ++i) {
      o << pad;
      write_json(o, j[i], indent + 2);
      o << (i + 1 < j.size() ? ",\n" : "\n");
    }
    o << std::string(indent, ' ') << "]";
  } else if (j.is_array()) {
    o << "[";
    for (std::size_t i = 0; i < j.size(); ++i) {
      o << (i ? ", " : "");
      write_json(o, j[i], indent);
    }
    o << "]";
  } else {
    o << j.dump();
  }
}

}  // namespace

std::string readable_json(const Json& doc) {
  std::ostringstream o;
  write_json(o, doc, 0);
  o << "\n";
  return o.str();
}

}  // namespace femdyn
