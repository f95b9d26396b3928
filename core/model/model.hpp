// Model: a compiled mechanism, immutable after compile(). Flat arrays in tree order.
//
// The transform levels (docs/notation.md):
//   q (n)  --coupling-->  θ (nθ) = C q + θ0
//   θ      --tree------>  body frames (R_b, p_b) along the tree, parents first
//   bodies --nodes----->  u (N_u): node translations (world axes) and body rotations (body axes)
// The correlation table N_m maps each element's local DOFs onto u.
#pragma once
#include <Eigen/Sparse>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/model/coupling_level.hpp"
#include "core/model/element.hpp"
#include "core/model/joint_type.hpp"
#include "core/model/loop_constraint.hpp"
#include "core/model/prescribed_motion.hpp"
#include "core/model/routes.hpp"
#include "core/model/spanning_mass.hpp"
#include "core/model/two_point_spring.hpp"
#include "core/spatial/spatial.hpp"

namespace femdyn {

using SpMat = Eigen::SparseMatrix<double>;
using SpRowMat = Eigen::SparseMatrix<double, Eigen::RowMajor>;

struct Joint {
  std::string name;
  JointType type = JointType::Fixed;
  Mat3 R_pj = Mat3::Identity();  // joint frame orientation in the parent body frame
  Vec3 p_pj = Vec3::Zero();      // joint frame origin in the parent body frame
  Vec3 axis = Vec3::UnitZ();     // unit, joint frame
  Vec3 axis2 = Vec3::UnitX();    // unit: universal's second axis (B), planar's e₁ (joint frame)
  double pitch = 0;              // helical: advance per turn of θ, m/rad
  int nq = 0, nv = 0;            // its coordinates and rates (core/joints/kernel.hpp)
  int idx_q = -1, idx_v = -1;    // its first coordinate in θ, first rate in θ̇; -1 when fixed
  double lower = 0, upper = 0;
  double stiffness = 0, rest = 0, damping = 0;
  double initial = 0;  // θ in the model's initial configuration (1-DOF joints; JSON "initial")
  // Actuator and friction (core/joints/passive.hpp; 1-DOF joints, but a rotor and a damper also
  // on spherical and free joints): rotor inertia I_a and
  // gear ratio G (reflected inertia I_a G² on θ̇, derived below), Coulomb friction F_c with its
  // regularisation velocity v_s, effort and velocity limits (+inf: none), and an enforced stop at
  // [lower, upper] (Simbody's MobilityLinearStop: stiffness k, Hunt–Crossley dissipation d).
  double armature = 0, gear = 1;
  double friction = 0, friction_velocity = 0.01;
  double effort_limit = INFINITY, velocity_limit = INFINITY;
  bool stop = false;
  double stop_stiffness = 1e4, stop_dissipation = 0.5;
  bool actuated = true;          // an actuator drives its rates (docs/control.md#actuation)
  double sample_range = 0;       // > 0: random postures draw within ± this (JointSpec's)
  double reflected_inertia = 0;  // derived: I_a G²
  std::string where;
  // Derived by compile() for the pose (core/joints/): R_pj [a]×, R_pj [a]×², R_pj a.
  Mat3 R_pj_K = Mat3::Zero(), R_pj_K2 = Mat3::Zero();
  Vec3 axis_parent = Vec3::UnitZ();
  Vec3 axis2_parent = Vec3::UnitX(), axis3_parent = Vec3::UnitY();  // planar: R_pj e₁, R_pj e₂
};

struct Body {
  std::string name;
  int parent = -1;  // body index, -1 for the world
  Joint joint;      // joint to the parent; the body frame is the joint frame after motion
  std::string where;
};

// A point that carries translation DOFs (x y z, world axes). Coincident element nodes share one.
struct SystemNode {
  int body = -1;          // carrier body (the shallowest body on which the point is fixed)
  Vec3 r = Vec3::Zero();  // body frame
  std::string label;
};

// A joint that owns generalized coordinates (no coupling sets it), with its first entry in q
// (n_q) and in v (n): MuJoCo's jnt_qposadr/jnt_dofadr, one level up past the couplings. Without
// couplings these are the joint's own idx_q and idx_v.
struct CoordinateJoint {
  int body = -1;
  int q = 0, v = 0;
};

// A frame fixed on a body (core/kinematics/frames.hpp): every body is one (its own frame, by its
// name), and a model names more (JSON "frames"). R_BF, p_BF place it in the body frame.
struct Frame {
  std::string name;
  int body = -1;
  Mat3 R_BF = Mat3::Identity();
  Vec3 p_BF = Vec3::Zero();
};

enum class DofKind : unsigned char { Translation, Rotation };

// One transition coordinate u_i: a translation of a node or a rotation rate of a body.
struct SystemDof {
  DofKind kind = DofKind::Translation;
  int carrier = 0;  // node index (translation) or body index (rotation)
  int axis = 0;     // 0, 1, 2
};

struct ElementEntry {
  std::shared_ptr<const Element> element;  // immutable, shared by copies of a spec
  int body = -1;
  std::vector<std::string> node_labels;
  std::vector<int> table_row;  // N_m row: 6 per node, 1-based system DOF number, 0 = left out
  std::vector<int> node_body;  // the body each node is fixed on (e.body unless it spans)
  bool spans = false;          // some node lies on another body (no body-level condensation)
  std::string where;
};

struct BodyTorque {
  int body;
  Vec3 torque;  // world frame
};

// A constant external force as given (kept for twins and reports; F_constant holds it on nodes).
struct PointLoad {
  int body;
  Vec3 point;  // body frame
  Vec3 force;  // world frame
};

// The routes, chosen once by compile() from the model's structure and an operation count
// (docs/performance.md gives the measured crossovers); the algorithms only dispatch on them.
enum class MassRoute {
  Transform,  // M^s = Tᵀ (M T) with T formed row by row: cheapest for a few bodies
  Composite   // M^s by composite body inertias (core/dynamics/body_inertia.hpp): O(bodies · depth)
};
enum class ForceRoute {
  Nodes,  // h, τ by node-level sweeps: Tᵀ (M T'[q̇,q̇] + g) by apply_transpose (core/kinematics)
  Bodies  // h, τ by recursive Newton–Euler over the body inertias Λ_b
          // (core/dynamics/newton_euler.hpp)
};
enum class DynamicsRoute {
  Cholesky,    // q̈ = (M^s)⁻¹ (Q − h): evaluate, then dense or CHOLMOD Cholesky
  Articulated  // articulated-body recursion over the element-assembled Λ_b
               // (core/dynamics/articulated.hpp)
};
// Routes asked of compile() instead of those it would choose (CompileOptions::routes,
// compile/compile.hpp): tests and benchmarks compare each route with its reference. A reference
// route (Transform, Nodes, Cholesky) is exact on every model; a body-level one asked where it is
// not exact is refused.
struct RouteChoice {
  std::optional<MassRoute> mass;
  std::optional<ForceRoute> force;
  std::optional<DynamicsRoute> dynamics;
};
// How the Cholesky route factorises M^s (core/workspace/mass_solver.hpp).
enum class SolverKind {
  Dense,   // LLT
  Sparse,  // CHOLMOD, fill-reducing order found once at compile
  Tree     // Featherstone's fill-free LTDL over the coordinate tree
};

// The structure of M^s, analysed once by compile() (analyse_mass_pattern,
// compile/routes.cpp, from core/workspace/mass_pattern.hpp) and shared by every Workspace.
struct MassPattern {
  SolverKind solver = SolverKind::Dense;
  std::vector<int> coordinate_parent;  // Tree: λ(a) < a, -1 at a root
  std::vector<int> sparse_order;       // Sparse: position k of the factorised matrix holds
                                       // coordinate sparse_order[k]
};

// A flexible bar's centreline: the bodies whose origins lie on it, in order from the clamp (the
// clamp's piece, each part's joint, the tip), and the section's polar radius of gyration
// √((ρI_y + ρI_z)/ρA) (m; a thin tube's radius), which a drawing gives the bar.
struct BarCentreline {
  std::string name;
  std::vector<int> stations;
  double radius = 0;
};

struct Model {
  Model() = default;
  // Movable into containers. Eigen 3.4's SparseMatrix has no move constructor, so moving M
  // copies it: an out-of-memory there terminates rather than throws.
  Model(Model&&) noexcept = default;
  Model& operator=(Model&&) noexcept = default;
  // A copy only where asked for by name (a law model starts as a copy of its tree), never by
  // accident.
  Model copy() const { return Model(*this); }

  std::string name;
  std::string where;  // the source, for messages
  Vec3 gravity = Vec3::Zero();
  std::vector<Body> bodies;      // parents before children
  std::vector<Frame> frames;     // the bodies' own (in body order), then the named ones
  std::vector<int> theta_joint;  // θ index -> body index of its joint
  std::vector<int> rate_parent;  // θ̇ index -> λ, the rate before it on its path to the world
                                 // (a joint's previous column, else the last rate of the nearest
                                 // moving ancestor joint); -1 at the world. λ(i) < i.

  // Coupling level θ = C q + θ0 (nθ x n, sparse: the identity is n entries, not n²).
  SpMat C;
  VecX theta0;
  std::vector<std::string> coordinate_names;  // n: the independent rates v (q̇ for 1-DOF joints)
  std::vector<std::string> configuration_names;    // n_q: the entries of q (e.g. base.qw)
  int n_theta_q = 0;                               // the joints' coordinates θ (Σ nq)
  std::vector<CoordinateJoint> coordinate_joints;  // tree order: q and v joint by joint

  // Node level.
  std::vector<SystemNode> nodes;
  std::vector<SystemDof> dofs;                   // u
  std::vector<std::array<int, 3>> node_dof;      // node -> u index per axis, -1 if left out
  std::vector<std::array<int, 3>> body_rot_dof;  // body -> u index per axis, -1 if left out
  std::vector<std::pair<int, int>> dof_alias;    // (copy, original): an explicit table may give
                                                 // one motion two numbers (the paper's u12, u16)
  std::vector<std::string> left_out;             // descriptions of DOFs left out, and why
  bool explicit_table = false;
  std::vector<std::string> approximations;  // joins made by an explicit table
  // Each flexible bar's centreline as built (docs/flexible.md), for drawing: the equations see
  // only its bodies.
  std::vector<BarCentreline> bars;

  std::vector<ElementEntry> elements;
  SpMat M;          // system lumped mass, N_u x N_u
  VecX F_constant;  // nodal forces that do not depend on the state (gravity, point loads)
  std::vector<BodyTorque> torques;
  std::vector<PointLoad> point_loads;
  // Coordinates whose motion is given in time (driven joints; sim/motion.cpp holds them).
  std::vector<PrescribedCoordinate> prescribed;
  // Body level (core/dynamics/body_inertia.hpp): M^s = Σ_b J_bᵀ Λ_b J_b where `condensable`.
  std::vector<RigidInertia>
      body_inertia;                // Λ_b = Σ X_eᵀ m_e X_e, body axes (core/spatial/spatial.hpp)
  bool identity_coupling = false;  // C = I and θ0 = 0: the coupling level is nothing
  SpRowMat C_sparse;               // C for the hot path (core/kinematics/coupling.hpp)
  // The configuration's form of C and θ0: θ (n_θq) = C_q q + θ0_q (q of n_q entries). A joint
  // with nq ≠ nv is never coupled: its nq rows are the identity on its own entries of q. Equal to
  // C and θ0 when every joint is flat; unused with the identity.
  SpRowMat C_configuration;
  VecX theta0_configuration;
  bool condensable = false;            // the body-level form is exact for this model
  bool condensable_off_spans = false;  // exact for every element but those spanning bodies
  // Elements spanning bodies kept on the body-level routes as their own terms
  // (core/dynamics/span_inertia.hpp); empty unless the routes are body-level and the model has
  // some.
  std::vector<SpanningMass> spanning_masses;
  bool velocity_forces_rigid = false;  // every g_e is its element's gyroscopic term (checked)
  MassRoute mass_route = MassRoute::Transform;             // how evaluate() forms M^s
  ForceRoute force_route = ForceRoute::Nodes;              // how h and τ are computed
  DynamicsRoute dynamics_route = DynamicsRoute::Cholesky;  // how forward_dynamics() finds q̈
  MassPattern mass_pattern;                                // the Cholesky route's solver
  EquationRoutes routes;  // what each equations function calls, chosen once (core/model/routes.hpp)

  // A nonlinear coupling level θ = g(q) (core/model/coupling_level.hpp), or null. With one, C and
  // θ0 above are only g's linearisation at compile time (its structure, for analyses and reports;
  // a zero slope there is stored as 1 so that no dependence is lost) and the equations are
  // those of `tree`, this mechanism with every joint a coordinate, reduced through g
  // (core/dynamics/coupling_chain.hpp).
  std::shared_ptr<const CouplingLevel> coupling_level;
  std::shared_ptr<const Model> tree;

  // Actuators (core/joints/passive.hpp), decided once by compile(): the reflected rotor
  // inertia on q, M_a = Cᵀ diag(I_a G²) C (n × n; empty without armature), and each rate's
  // effort limit |τ_i| ≤ effort_limit_i of its joint (+inf: none; empty without limits).
  bool has_armature = false;
  SpMat armature_mass;
  // The free joints' rotors (core/joints/rotor.hpp): their velocity term a ω × v, at q̇'s rate
  // `v` (the joint's first, linear rate; ω follows at v + 3), θ̇'s rate `theta`, a = I_a G².
  // Empty on a model with a coupling law: its tree's equations hold them.
  struct FreeRotor {
    int v = 0, theta = 0;
    double a = 0;
  };
  std::vector<FreeRotor> free_rotors;
  // The spherical and free joints' dampers (core/joints/passive.hpp): −c on each of the `nv`
  // rates from q̇'s `v` (θ̇'s `theta`). Empty on a model with a coupling law, as free_rotors.
  struct RateDamper {
    int v = 0, theta = 0, nv = 0;
    double c = 0;
  };
  std::vector<RateDamper> rate_dampers;
  // The flexible bars' mass-proportional and modal damping (compile/bar_damping.hpp): a
  // generalized force −D q̇, D (n × n) constant, symmetric and positive semi-definite, on the
  // bars' own rates. Empty without.
  SpMat rate_damping;
  bool has_rate_damping = false;
  VecX effort_limit;
  bool has_effort_limits = false;
  // Actuation (docs/control.md#actuation): the rates of q an actuator drives, ascending (n_a of
  // them). τ = S u with S = I[:, actuated] (n × n_a): a controller's τ is zero on the others (a
  // free base, passive loop joints), and the linearisation's B has these columns.
  std::vector<int> actuated;
  int n_actuated() const { return static_cast<int>(actuated.size()); }
  bool fully_actuated() const { return n_actuated() == n(); }

  // Loops closed by constraints Φ(q) = 0 on the spanning tree (core/loops/), and two-point
  // springs (core/dynamics/springs.hpp). Empty for a tree without them.
  std::vector<LoopConstraint> constraints;
  int constraint_rows = 0;  // m = Σ rows: Φ_q is m × n
  std::vector<TwoPointSpring> springs;

  bool has_nodal_forces = false;     // gravity or loads present
  bool has_velocity_forces = false;  // some element has a gyroscopic term

  int n() const { return static_cast<int>(C.cols()); }  // rates v: M^s is n × n
  int n_q() const { return static_cast<int>(configuration_names.size()); }  // coordinates q
  int n_theta() const { return static_cast<int>(theta_joint.size()); }
  int n_u() const { return static_cast<int>(dofs.size()); }
  std::string dof_name(int i) const { return dof_name_of(dofs.at(i)); }
  std::string dof_name_of(const SystemDof& d) const;  // e.g. "link2/tip.x" or "link2.rz"

 private:
  Model(const Model&) = default;
};

// (Defined here, with the Model it names, not in compile/: core keeps its own symbols.)
inline std::string Model::dof_name_of(const SystemDof& d) const {
  static constexpr const char* kAxes[] = {"x", "y", "z"};
  if (d.kind == DofKind::Translation) return nodes[d.carrier].label + "." + kAxes[d.axis];
  return bodies[d.carrier].name + ".r" + kAxes[d.axis];
}

}  // namespace femdyn
