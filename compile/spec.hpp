// MechanismSpec: a mechanism as described by the user, before compilation. Front ends (io/)
// fill it; compile() (compile/compile.cpp) turns it into an immutable Model. Every part carries
// `where`, the label of its place in the source file ("file.json: /bodies/3"), used in error
// messages; compile appends JSON-pointer segments to it to name a field.
#pragma once
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/model/coupling_function.hpp"
#include "core/model/element.hpp"
#include "core/model/joint_type.hpp"
#include "core/model/prescribed_motion.hpp"

namespace femdyn {

struct JointSpec {
  std::string name;
  JointType type = JointType::Fixed;
  Vec3 xyz = Vec3::Zero();              // joint frame origin in the parent body frame
  Vec3 rpy = Vec3::Zero();              // joint frame orientation, R = Rz(y) Ry(p) Rx(r)
  std::optional<Eigen::Vector4d> quat;  // or as a quaternion (w, x, y, z), normalised on compile
  Vec3 axis = Vec3::UnitZ();            // in the joint frame (normalised on compile)
  std::optional<Vec3> axis2;            // universal: the second axis, normal to `axis` (required)
  std::map<std::string, double>
      scalars;  // the type's own numbers by key (core/joints/parameters.hpp)
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  double stiffness = 0, rest = 0, damping = 0;    // linear spring / damper on θ
  double initial = 0;                             // θ in the initial configuration
  double armature = 0, gear = 1;                  // rotor inertia I_a, gear ratio G
  double friction = 0, friction_velocity = 0.01;  // Coulomb F_c, regularisation v_s
  double effort_limit = std::numeric_limits<double>::infinity();
  double velocity_limit = std::numeric_limits<double>::infinity();
  bool stop = false;  // enforce [lower, upper] by a stiff stop (core/joints/passive.hpp)
  double stop_stiffness = 1e4, stop_dissipation = 0.5;
  // Whether an actuator drives the joint's rates (docs/control.md#actuation); not given: every
  // joint but a free one (a floating base has no thrusters unless the model says so).
  std::optional<bool> actuated;
  // > 0: random states (check, stress, validate) draw the coordinate within ± this (a flexible
  // bar's strains); 0: the joint type's range narrowed to the limits.
  double sample_range = 0;
  // A driven joint: its coordinate follows this motion in time (one-rate joints).
  std::optional<PrescribedMotion> prescribed;
  std::string where;
};

struct ElementSpec {
  std::shared_ptr<const Element> element;  // immutable, shared by copies of a spec
  std::vector<std::string> node_labels;    // one per element node (for tables)
  std::string where;
};

struct BodySpec {
  std::string name;
  std::string parent;  // "world" for the ground
  JointSpec joint;
  std::vector<ElementSpec> elements;
  std::string where;
};

// θ_joint = Σ ratio_i θ_{follows_i} + offset   (the coupling level θ = C q + θ0), or with a
// `law`: θ_joint = law(θ_{follows_1}, θ_{follows_2}, …) (the level θ = g(q)).
struct CouplingSpec {
  std::string joint;
  std::vector<std::pair<std::string, double>> terms;  // linear
  double offset = 0;
  std::shared_ptr<const CouplingFunction> law;  // nonlinear (then `terms` is empty)
  std::vector<std::string> follows;             // the law's arguments, in order
  std::string where;
};

// Constant external force (world frame, N) at a point of a body (body frame),
// and/or a constant torque (world frame, N·m) on the body.
struct LoadSpec {
  std::string body;
  Vec3 point = Vec3::Zero();
  Vec3 force = Vec3::Zero();
  Vec3 torque = Vec3::Zero();
  std::string where;
};

// Explicit correlation table: one row per element (in file order), 6 entries per element
// node, each a 1-based system DOF number or 0 (left out).
// join_deepest: a number may join local DOFs that move differently (the paper's shared hinge
// rotations); the system DOF then takes the motion of the one on the deepest body. This is an
// approximation, listed by `femdyn info`; by default each number must name one motion.
struct CorrelationSpec {
  std::vector<std::vector<int>> rows;
  bool join_deepest = false;
  std::string where;
};

// A named frame fixed on a body: its origin at `xyz` (or at a node of the body) and its axes
// turned by `rpy` from the body's (docs/model-format.md#frames).
struct FrameSpec {
  std::string name, body;
  Vec3 xyz = Vec3::Zero(), rpy = Vec3::Zero();
  std::string where;
};

// One end of a loop constraint or a two-point spring: a named frame, a body's own frame, or
// "world" (`frame`), or else a point `xyz` on `body` with axes turned by `rpy`.
struct AttachmentSpec {
  std::string frame;
  std::string body;
  Vec3 xyz = Vec3::Zero(), rpy = Vec3::Zero();
  std::string where;
};

// A loop-closure constraint (core/model/loop_constraint.hpp; docs/model-format.md#constraints).
struct ConstraintSpec {
  std::string name;
  std::string type;          // ball, weld, distance, point_on_line, point_on_plane, gear
  AttachmentSpec a, b;       // all but gear
  std::optional<Vec3> axis;  // ball's plane normal, point_on_plane's normal, the line direction
  double length = 0;         // distance
  // gear: θ_joint = Σ ratio θ_follows + offset
  std::string joint;
  std::vector<std::pair<std::string, double>> terms;
  double offset = 0;
  std::string where;
};

// A linear spring-damper between two places (core/dynamics/springs.hpp).
struct SpringSpec {
  std::string name;
  AttachmentSpec a, b;
  double stiffness = 0, rest_length = 0, damping = 0;
  std::string where;
};

// A flexible bar (io/flexible_bar.hpp): its centreline (Model::bars, its stations by body
// name), its elastic joints in order, and the damping compile builds on them (Model::
// rate_damping): mass-proportional α M̄ and modal, ratio ζ_k for mode k (the last for the rest).
struct BarSpec {
  std::string name;
  std::vector<std::string> stations;
  double radius = 0;
  std::vector<std::string> joints;
  double mass_proportional = 0;
  std::vector<double> modal;
  std::string where;
};

struct MechanismSpec {
  std::string name;
  Vec3 gravity = Vec3::Zero();
  std::string gravity_where;  // where gravity was given, for messages (empty: the file's /gravity)
  std::vector<BodySpec> bodies;
  std::vector<CouplingSpec> couplings;
  std::vector<LoadSpec> loads;
  std::vector<FrameSpec> frames;
  std::vector<ConstraintSpec> constraints;
  std::vector<SpringSpec> springs;
  std::vector<BarSpec> bars;
  std::optional<CorrelationSpec> correlation;
  std::string where;  // the file
};

}  // namespace femdyn
