// femdyn.Builder: a mechanism described in Python without JSON (models/builder.hpp), compiled to
// a femdyn.Model. Couplings are given in the JSON format's words (ratio, offset, polynomial,
// spline, four_bar) and read by the loader's own reader (io parse_coupling).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <variant>

#include "core/joints/kernel.hpp"
#include "core/model/names.hpp"
#include "elements/space_bar.hpp"
#include "models/builder.hpp"
#include "models/model_files.hpp"
#include "python/py_model.hpp"

namespace femdyn::python {
namespace {

// A Python value (dict, list, tuple, str, bool, int, float, None) as JSON, for a coupling.
Json to_json(const py::handle& v, const std::string& name) {
  if (v.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>();
  if (py::isinstance<py::int_>(v)) return v.cast<long long>();
  if (py::isinstance<py::float_>(v)) return v.cast<double>();
  if (py::isinstance<py::str>(v)) return text_arg(v.cast<std::string>(), name.c_str());
  if (py::isinstance<py::dict>(v)) {
    Json out = Json::object();
    for (const auto& [key, value] : v.cast<py::dict>()) {
      if (!py::isinstance<py::str>(key)) throw py::type_error(name + ": keys must be strings");
      out[text_arg(key.cast<std::string>(), name.c_str())] = to_json(value, name);
    }
    return out;
  }
  if (py::isinstance<py::sequence>(v) || py::isinstance<py::array>(v)) {
    Json out = Json::array();
    for (const py::handle item : py::iter(v)) out.push_back(to_json(item, name));
    return out;
  }
  try {  // a numpy scalar or anything float() accepts
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  } catch (const py::error_already_set&) {
    throw py::type_error(name + ": cannot use a " +
                         std::string(py::str(v.get_type().attr("__name__"))) + " here");
  }
}

// (3,) finite, as Vec3.
Vec3 vec3_arg(const Array& a, const char* name) {
  if (a.ndim() != 1 || a.shape(0) != 3)
    throw py::value_error(std::string(name) + ": expected shape (3,), got " + shape_text(a));
  const Vec3 v(a.data()[0], a.data()[1], a.data()[2]);
  if (!v.allFinite()) throw py::value_error(std::string(name) + ": NaN or Inf");
  return v;
}

// (3, 3) finite, as Mat3.
Mat3 mat3_arg(const Array& a, const char* name) {
  if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    throw py::value_error(std::string(name) + ": expected shape (3, 3), got " + shape_text(a));
  Mat3 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = a.data()[3 * i + j];
  if (!m.allFinite()) throw py::value_error(std::string(name) + ": NaN or Inf");
  return m;
}

// A node: its name (str) or a position (3,).
NodeDescription node_arg(const py::object& node, const char* name) {
  if (py::isinstance<py::str>(node)) return text_arg(node.cast<std::string>(), name);
  return vec3_arg(node.cast<Array>(), name);
}

using OptArray = std::optional<Array>;
using OptNumber = std::optional<double>;

// Builder.body's actuator, friction and stop arguments (None: not given). `stop`: None, a bool,
// or a dict {"stiffness": k, "dissipation": d} (docs/model-format.md).
struct ActuatorArgs {
  OptNumber armature, gear, friction, friction_velocity, effort_limit, velocity_limit;
  py::object stop = py::none();
  std::optional<bool> actuated;
  bool given() const {
    return armature || gear || friction || friction_velocity || effort_limit || velocity_limit ||
           !stop.is_none() || actuated;
  }
};

void actuator_arg(const ActuatorArgs& a, JointSpec& j) {
  if (j.type == JointType::Fixed && a.given())
    throw py::value_error("a fixed joint has no motion: no actuator, friction or stop");
  j.armature = a.armature.value_or(j.armature);
  j.gear = a.gear.value_or(j.gear);
  j.friction = a.friction.value_or(j.friction);
  j.friction_velocity = a.friction_velocity.value_or(j.friction_velocity);
  j.effort_limit = a.effort_limit.value_or(j.effort_limit);
  j.velocity_limit = a.velocity_limit.value_or(j.velocity_limit);
  j.actuated = a.actuated;
  if (a.stop.is_none()) return;
  if (py::isinstance<py::bool_>(a.stop)) {
    j.stop = a.stop.cast<bool>();
    return;
  }
  if (!py::isinstance<py::dict>(a.stop))
    throw py::type_error("stop: expected True or a dict {'stiffness': k, 'dissipation': d}");
  j.stop = true;
  for (const auto& [key, value] : a.stop.cast<py::dict>()) {
    const std::string k = py::str(key);
    if (k == "stiffness")
      j.stop_stiffness = value.cast<double>();
    else if (k == "dissipation")
      j.stop_dissipation = value.cast<double>();
    else
      throw py::value_error("stop: unknown key " + quoted_text(k) +
                            " (expected stiffness, dissipation)");
  }
}

// A joint type's own numbers (core/joints/parameters.hpp), given as keywords: a helical joint's
// pitch. A keyword no type takes is a TypeError, as Python's own; one another type takes, or a
// number that is not finite, a ValueError naming it.
void scalar_args(const py::kwargs& scalars, JointSpec& j) {
  for (const auto& [k, v] : scalars) {
    const std::string key = py::cast<std::string>(k);
    if (!is_joint_scalar(key))
      throw py::type_error("body() got an unexpected keyword argument " + quoted_text(key));
    if (!joint_scalar(j.type, key)) throw py::value_error(key + ": " + joint_scalar_refusal(key));
    double x = 0;
    try {
      x = py::cast<double>(v);
    } catch (const py::cast_error&) {
      throw py::value_error(key + ": expected a number");
    }
    if (!std::isfinite(x)) throw py::value_error(key + ": NaN or Inf");
    j.scalars[key] = x;
  }
}

// Builder.body's joint: `type` and the arguments that describe the joint, each None when not
// given. Without a type the body is welded to its parent (a fixed joint at its origin), so a
// joint argument without one is refused: it would be ignored, or (xyz, rpy) weld a body that
// was meant to move. With type='fixed', the motion's arguments (axis, limits, spring, damper)
// are refused as the JSON loader refuses them on a fixed joint.
JointSpec joint_arg(const std::optional<std::string>& type_in,
                    const std::optional<std::string>& name, const OptArray& axis,
                    const OptArray& xyz, const OptArray& rpy,
                    const std::optional<std::pair<double, double>>& limits, OptNumber stiffness,
                    OptNumber rest, OptNumber damping, const OptArray& axis2,
                    const py::kwargs& scalars) {
  const std::pair<const char*, bool> motion[] = {
      {"axis", axis.has_value()},
      {"axis2", axis2.has_value()},
      {"limits", limits.has_value()},
      {"stiffness", stiffness.has_value()},
      {"rest", rest.has_value()},
      {"damping", damping.has_value()},
      {"the type's own numbers (such as pitch)", !scalars.empty()}};
  if (!type_in) {
    for (const auto& [arg, given] :
         {std::pair{"joint", name.has_value()}, {"xyz", xyz.has_value()}, {"rpy", rpy.has_value()}})
      if (given)
        throw py::value_error(std::string(arg) +
                              ": given without a joint type; a body without type= is welded to "
                              "its parent (say type='revolute', 'prismatic', or 'fixed' to weld "
                              "it)");
    for (const auto& [arg, given] : motion)
      if (given)
        throw py::value_error(std::string(arg) +
                              ": given without a joint type; a body without type= is welded to "
                              "its parent (say type='revolute' or 'prismatic')");
  }
  const std::string type = type_in.value_or("fixed");
  JointSpec j;
  if (const auto named = joint_type_named(type))
    j.type = *named;
  else
    throw py::value_error("joint type: unknown " + quoted_text(type) + " (expected " +
                          joint_type_list() + ")");
  if (j.type == JointType::Fixed)
    for (const auto& [arg, given] : motion)
      if (given)
        throw py::value_error(std::string(arg) +
                              ": a fixed joint has no motion: no axis, limits, spring or damping");
  if (const JointParameters p = joint_parameters(j.type);
      p.moves && p.axes == JointAxes::None && axis)
    throw py::value_error("axis: " + joint_axis_refusal(j.type));
  if (name) j.name = *name;
  if (axis) j.axis = vec3_arg(*axis, "axis");
  if (axis2) j.axis2 = vec3_arg(*axis2, "axis2");  // (compile: universal only)
  scalar_args(scalars, j);
  if (xyz) j.xyz = vec3_arg(*xyz, "xyz");
  if (rpy) j.rpy = vec3_arg(*rpy, "rpy");
  if (limits) {
    if (std::isnan(limits->first) || std::isnan(limits->second))
      throw py::value_error("limits: NaN");
    j.lower = limits->first, j.upper = limits->second;
  }
  j.stiffness = stiffness.value_or(0), j.rest = rest.value_or(0), j.damping = damping.value_or(0);
  return j;
}

}  // namespace

void bind_builder(py::module_& m) {
  py::class_<MechanismBuilder>(m, "Builder",
                               "A mechanism described in code: bodies, nodes, elements, "
                               "couplings, loads; build() compiles it (docs/python.md)")
      .def(py::init([](const std::string& name, const std::optional<Array>& gravity) {
             auto b = std::make_unique<MechanismBuilder>(text_arg(name, "name"));
             if (gravity) b->gravity(vec3_arg(*gravity, "gravity"));
             return b;
           }),
           py::arg("name"), py::arg("gravity") = py::none())
      .def(
          "body",
          [](MechanismBuilder& b, const std::string& name, const std::string& parent,
             const std::optional<std::string>& type, const std::optional<std::string>& joint,
             const OptArray& axis, const OptArray& xyz, const OptArray& rpy,
             const std::optional<std::pair<double, double>>& limits, OptNumber stiffness,
             OptNumber rest, OptNumber damping, const OptArray& axis2, OptNumber armature,
             OptNumber gear, OptNumber friction, OptNumber friction_velocity,
             OptNumber effort_limit, OptNumber velocity_limit, const py::object& stop,
             OptNumber initial, std::optional<bool> actuated, OptNumber sample_range,
             const py::kwargs& scalars) {
            const ActuatorArgs act{armature,     gear,           friction, friction_velocity,
                                   effort_limit, velocity_limit, stop,     actuated};
            if (!type && act.given())
              throw py::value_error(
                  "actuator, friction or stop: given without a joint type; a body without "
                  "type= is welded to its parent (say type='revolute' or 'prismatic')");
            JointSpec j = joint_arg(text_arg(type, "type"), text_arg(joint, "joint"), axis, xyz,
                                    rpy, limits, stiffness, rest, damping, axis2, scalars);
            actuator_arg(act, j);
            if (initial) j.initial = *initial;
            if (sample_range) {  // (compile: finite, and a joint of one coordinate)
              if (!(*sample_range > 0)) throw py::value_error("sample_range: must be positive");
              j.sample_range = *sample_range;
            }
            b.body(text_arg(name, "name"), text_arg(parent, "parent"), std::move(j));
          },
          py::arg("name"), py::arg("parent") = "world", py::arg("type") = py::none(),
          py::arg("joint") = py::none(), py::arg("axis") = py::none(), py::arg("xyz") = py::none(),
          py::arg("rpy") = py::none(), py::arg("limits") = py::none(),
          py::arg("stiffness") = py::none(), py::arg("rest") = py::none(),
          py::arg("damping") = py::none(), py::arg("axis2") = py::none(),
          py::arg("armature") = py::none(), py::arg("gear") = py::none(),
          py::arg("friction") = py::none(), py::arg("friction_velocity") = py::none(),
          py::arg("effort_limit") = py::none(), py::arg("velocity_limit") = py::none(),
          py::arg("stop") = py::none(), py::arg("initial") = py::none(),
          py::arg("actuated") = py::none(), py::arg("sample_range") = py::none(),
          "A body on `parent` ('world': the ground) by a joint of `type` (revolute, prismatic, "
          "fixed, helical, universal, planar, spherical, free; docs/notation.md) named `joint` "
          "(default: the body's name), at xyz, rpy (default 0), about axis (default (0, 0, 1)), "
          "with limits (lower, upper), a spring (stiffness, rest) and a damper; a universal "
          "joint's second axis `axis2`, the type's own numbers as keywords (a helical joint's "
          "`pitch`, m/rad; docs/model-format.md); a rotor `armature` "
          "(kg·m²) behind a `gear` ratio, Coulomb `friction` regularised at `friction_velocity`, "
          "`effort_limit`, `velocity_limit`, and `stop` (True or {'stiffness': k, "
          "'dissipation': d}) enforcing the limits (docs/control.md), `actuated` (default: True "
          "but on a free joint; docs/control.md#actuation), the joint's `initial` "
          "coordinate (the start of a run) and `sample_range` (the half range random states "
          "draw it from: check, stress, validate; docs/model-format.md). Without type the body "
          "is welded to its parent's origin and no other joint argument may be given (ValueError "
          "naming it); a fixed joint takes no axis, limits, spring or damper.")
      .def(
          "node",
          [](MechanismBuilder& b, const std::string& body, const std::string& name,
             const Array& position) {
            b.node(text_arg(body, "body"), text_arg(name, "name"), vec3_arg(position, "position"));
          },
          py::arg("body"), py::arg("name"), py::arg("position"))
      .def(
          "lumped_point",
          [](MechanismBuilder& b, const std::string& body, const py::object& node, double mass) {
            b.lumped_point(text_arg(body, "body"), node_arg(node, "node"), mass);
          },
          py::arg("body"), py::arg("node"), py::arg("mass"))
      .def(
          "rotary_node",
          [](MechanismBuilder& b, const std::string& body, const py::object& node,
             const Array& inertia) {
            b.rotary_node(text_arg(body, "body"), node_arg(node, "node"),
                          mat3_arg(inertia, "inertia"));
          },
          py::arg("body"), py::arg("node"), py::arg("inertia"))
      .def(
          "rigid_body",
          [](MechanismBuilder& b, const std::string& body, double mass, const Array& com,
             const Array& inertia) {
            b.rigid_body(text_arg(body, "body"), mass, vec3_arg(com, "com"),
                         mat3_arg(inertia, "inertia"));
          },
          py::arg("body"), py::arg("mass"), py::arg("com"), py::arg("inertia"),
          "mass, centre of mass and inertia about it (body axes)")
      .def(
          "space_bar",
          [](MechanismBuilder& b, const std::string& body, const py::object& a,
             const py::object& b_node, double mass, const Array& inertia) {
            b.space_bar(text_arg(body, "body"), node_arg(a, "a"), node_arg(b_node, "b"), mass,
                        mat3_arg(inertia, "inertia"));
          },
          py::arg("body"), py::arg("a"), py::arg("b"), py::arg("mass"), py::arg("inertia"),
          "a rigid bar from a to b of this mass and centroidal inertia")
      .def(
          "space_bar",
          [](MechanismBuilder& b, const std::string& body, const py::object& a,
             const py::object& b_node, double density, double area, double Iy, double Iz,
             const py::object& section_y) {
            BarSection section{density, area, Iy, Iz, std::nullopt};
            if (!section_y.is_none())
              section.section_y = vec3_arg(section_y.cast<Array>(), "section_y");
            b.space_bar(text_arg(body, "body"), node_arg(a, "a"), node_arg(b_node, "b"), section);
          },
          py::arg("body"), py::arg("a"), py::arg("b"), py::kw_only(), py::arg("density"),
          py::arg("area"), py::arg("Iy"), py::arg("Iz"), py::arg("section_y") = py::none(),
          "a uniform bar from a to b of this density, section area and second moments (I_y, I_z "
          "about the section's axes; section_y orients them)")
      .def(
          "rod",
          [](MechanismBuilder& b, const std::string& body, const py::object& a,
             const py::object& b_node, double mass) {
            b.rod(text_arg(body, "body"), node_arg(a, "a"), node_arg(b_node, "b"), mass);
          },
          py::arg("body"), py::arg("a"), py::arg("b"), py::arg("mass"),
          "a slender rod; a node 'other_body/name' lies on another body")
      .def(
          "coupling",
          [](MechanismBuilder& b, const std::string& joint, const py::object& follows,
             const py::kwargs& law) {
            Json c = to_json(law, "coupling");
            c["joint"] = text_arg(joint, "joint");
            c["follows"] = to_json(follows, "follows");
            b.coupling(parse_coupling(c, b.next_coupling()));
          },
          py::arg("joint"), py::arg("follows"),
          "θ_joint from the joint(s) it follows, in the JSON format's words: ratio=, offset=, "
          "or polynomial=, spline=, four_bar= (docs/model-format.md#couplings)")
      .def(
          "frame",
          [](MechanismBuilder& b, const std::string& name, const std::string& body,
             const Array& xyz, const Array& rpy) {
            b.frame(text_arg(name, "name"), text_arg(body, "body"), vec3_arg(xyz, "xyz"),
                    vec3_arg(rpy, "rpy"));
          },
          py::arg("name"), py::arg("body"), py::arg("xyz") = Vec3(0, 0, 0),
          py::arg("rpy") = Vec3(0, 0, 0), "a named frame on a body (its origin and axes)")
      .def(
          "constraint",
          [](MechanismBuilder& b, const std::string& type, const py::kwargs& fields) {
            Json c = to_json(fields, "constraint");
            c["type"] = text_arg(type, "type");
            b.constraint(parse_constraint(c, b.next_constraint(), b.constraint_count()));
          },
          py::arg("type"),
          "a loop constraint in the JSON format's words: type 'ball', 'weld', 'distance', "
          "'point_on_line', 'point_on_plane' with a=, b= (a frame, a body, 'world' or "
          "{'body': …, 'xyz': …}) and normal=, direction=, length=; or 'gear' with joint=, "
          "follows=, ratio=, offset=; name= (docs/loops.md)")
      .def(
          "flexible_bar",
          [](MechanismBuilder& b, const std::string& name, const std::string& parent,
             const py::kwargs& fields) {
            Json bar = to_json(fields, "flexible_bar");
            bar["name"] = text_arg(name, "name");
            bar["parent"] = text_arg(parent, "parent");
            b.flexible_bar(bar);
          },
          py::arg("name"), py::arg("parent"),
          "a flexible bar clamped to `parent` in the JSON format's words: length=, segments=, "
          "section={'E', 'G', 'density', 'area', 'Iy', 'Iz', 'J'} or {'EA', 'EIy', 'EIz', 'GJ', "
          "'rhoA', 'rhoIy', 'rhoIz'}, origin={'xyz', 'rpy'}, axial=, torsion=, "
          "damping={'stiffness_proportional': β, 'mass_proportional': α, 'modal': ζ}, "
          "curvature={'radius', 'axis'} "
          "(docs/model-format.md#flexible-bars)")
      .def(
          "spring",
          [](MechanismBuilder& b, const py::kwargs& fields) {
            b.spring(parse_spring(to_json(fields, "spring"), b.next_spring(), b.spring_count()));
          },
          "a two-point spring-damper: a=, b=, stiffness=, rest_length=, damping=, name=")
      .def(
          "load",
          [](MechanismBuilder& b, const std::string& body, const Array& point, const Array& force,
             const Array& torque) {
            b.load(text_arg(body, "body"), vec3_arg(point, "point"), vec3_arg(force, "force"),
                   vec3_arg(torque, "torque"));
          },
          py::arg("body"), py::arg("point") = Vec3(0, 0, 0), py::arg("force") = Vec3(0, 0, 0),
          py::arg("torque") = Vec3(0, 0, 0))
      .def(
          "build",
          [](const MechanismBuilder& b) {
            Model model;
            {
              py::gil_scoped_release release;
              model = b.build();
            }
            auto pm = std::make_unique<PyModel>(std::move(model));
            pm->spec = std::make_shared<const MechanismSpec>(b.spec());
            return pm;
          },
          "compile the mechanism (the checks of a JSON file's compile) into a femdyn.Model");
}

}  // namespace femdyn::python
