// SimbodyTwin: the same mechanism built in Simbody from a compiled femdyn Model, evaluated at
// femdyn's coordinates q. This header does not include Simbody (the twin lives in twin*.cpp,
// the only translation units that do, listed in twin_impl.hpp), so callers may be compiled with
// any flags.
//
// The twin's files are compiled as C++17 without NDEBUG (Simbody 3.7's headers do not compile as
// C++20, and must see the NDEBUG setting the library was built with), so this header and what the
// twin reads of a model (TwinModel) use Eigen and the standard library only.
//
// Mapping (docs/validation.md):
//   femdyn body b, joint (R_pj, p_pj, axis)  ->  MobilizedBody::Pin (revolute, turns about z),
//       ::Slider (prismatic, moves along x), ::Screw (helical, about and along z, the pitch),
//       ::Universal (about x, then the new y), ::Planar (about z, along x, y) or ::Weld
//       (fixed), with X_PF = (R_pj·R_a, p_pj), X_BM = (R_a, 0), R_a taking the mobilizer's axes
//       onto the joint's (z onto `axis`; x, y onto a₁, a₂; x, y, z onto e₁, e₂, n);
//       spherical -> ::Ball and free -> ::Free, with X_PF = (R_pj, p_pj), X_BM = 1 and
//       quaternions. Their rates differ: femdyn's v is in B's axes, Simbody's u in F's
//       (u = R_FM v per triple, the free joint's angular triple first), so u = P v with P
//       orthogonal and u̇ = P v̇ + Ṗ v (Ṗ v = (0, R_FM (ω × v)) for a free joint, 0 else):
//       M_v = Pᵀ M_u P, h_v = Pᵀ (h_u + M_u Ṗ v), Q_v = Pᵀ Q_u, forces in by P (P⁻ᵀ = P);
//   body mass properties = Σ of the body's equivalent elements' Element::mass_properties();
//   gravity -> Force::Gravity; springs/dampers -> MobilityLinearSpring / MobilityLinearDamper;
//   enforced joint stops -> MobilityLinearStop (the same law); Coulomb friction -> a
//   Force::Custom of femdyn's regularised law; a rotor's armature has no counterpart (refused);
//   point loads and torques -> Force::ConstantForce / ConstantTorque; τ -> applied mobility
//   forces; coupling θ = C q + θ0 -> exact reduction (pointwise) and
//   Constraint::CoordinateCoupler (trajectories).
// A model with a nonlinear coupling law or an element spanning two bodies is built closed-loop
// (TwinModel::closed_loop()): the tree of every joint; each coupled joint a
// Constraint::CoordinateCoupler whose Function is θ_t − f(θ_s…) with the law's exact gradient
// and Hessian, except the joint whose loop a spanning rod closes; each rod a rigid slender body
// on a MobilizedBody::LineOrientation at its first end (no inertia about its axis) and a
// Constraint::Ball at its second. Its equations come from Simbody's constrained forward
// dynamics alone (SimbodyMatterSubsystem::calcAcceleration), never from femdyn's reduction:
//   q̈ directly; (M^s)⁻¹ e_k = q̈(unit force on q_k) − q̈(no force); h = −M^s q̈(no force);
//   Q = M^s (q̈(Simbody's forces) − q̈(no force)) + τ;   τ(q̈) = M^s (q̈ − q̈(Simbody's forces)).
#pragma once
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/model/joint_type.hpp"

namespace femdyn::validation {

using MatX = Eigen::MatrixXd;
using VecX = Eigen::VectorXd;
using SpMatX = Eigen::SparseMatrix<double>;
using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// What the twin needs of a femdyn Model (built by twin_model() in twin_model.cpp).
struct TwinBody {
  std::string name;         // for messages ("Simbody refuses body 'x': …")
  int parent = -1;          // -1: the ground
  using Joint = JointType;  // (core/model/joint_type.hpp: plain C++17, no Eigen or Simbody)
  Joint joint = Joint::Fixed;
  Mat3 R_pj = Mat3::Identity();  // joint frame in the parent body frame
  Vec3 p_pj = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();   // unit, joint frame
  Vec3 axis2 = Vec3::UnitX();  // universal: a₂ (B); planar: e₁ (joint frame, ⊥ axis)
  std::map<std::string, double> scalars;  // the type's own numbers (helical: "pitch", m/rad)
  int theta = -1;                         // its first coordinate in θ (nq of them)
  int rate = -1;  // its first rate in θ̇ (nv of them; = theta for nq = nv)
  double stiffness = 0, rest = 0, damping = 0;
  // An enforced stop on [lower, upper] (Force::MobilityLinearStop, femdyn's law exactly).
  bool stop = false;
  double lower = 0, upper = 0, stop_stiffness = 0, stop_dissipation = 0;
  // Coulomb friction −F_c tanh(θ̇ / v_s) (a Force::Custom: Simbody has no such element).
  double friction = 0, friction_velocity = 1;
  double mass = 0;                     // Σ of the body's equivalent elements:
  Vec3 com = Vec3::Zero();             //   centre of mass (body frame)
  Mat3 inertia_origin = Mat3::Zero();  // inertia about the body origin (body frame)
};

// A coupled joint of the closed-loop twin: θ_theta = f(θ_sources…), f with its exact gradient
// and Hessian (a core CouplingFunction, passed as a callable: this header is read as C++17).
// `law` returns false where f is not defined; d2f is arity × arity, row-major.
struct TwinLaw {
  int theta = -1;
  std::vector<int> sources;  // θ indices, each a coordinate or a joint resolved before
  std::function<bool(const double* x, double& f, double* df, double* d2f)> law;
  std::string name;  // the coupled joint, for messages
};

// A uniform slender rigid rod (no inertia about its axis) of `mass` between point_a on body_a
// and point_b on body_b (body frames), `length` apart: an element that spans two bodies. It
// closes the loop of coupled joint θ `closes` (its Constraint::Ball replaces that coupler).
struct TwinRod {
  int body_a = -1, body_b = -1;
  Vec3 point_a = Vec3::Zero(), point_b = Vec3::Zero();
  double mass = 0, length = 0;
  int closes = -1;
  std::string name;  // the element's place in the file, for messages
};

// A loop constraint of the model (core/model/loop_constraint.hpp) as Simbody's
// (twin_constraints.hpp): places A and B fixed on bodies (body frames; −1 the ground) with axes R
// and origin p.
struct TwinConstraint {
  enum class Type { Ball, PointOnLine, PointInPlane, Weld, Rod, Gear } type = Type::Ball;
  std::string name;  // for messages
  int body_a = -1, body_b = -1;
  Mat3 R_a = Mat3::Identity(), R_b = Mat3::Identity();
  Vec3 p_a = Vec3::Zero(), p_b = Vec3::Zero();
  Vec3 direction = Vec3::UnitZ();  // PointOnLine: the line's (B's body frame); PointInPlane: n
  double length = 0;               // Rod
  // Gear: θ of bodies[0]'s joint = Σ ratios[i] θ of bodies[1 + i]'s + offset (1-DOF joints).
  std::vector<int> bodies;
  std::vector<double> ratios;
  double offset = 0;
};

// A two-point linear spring-damper (core/dynamics/springs.hpp): Force::TwoPointLinearSpring and
// Force::TwoPointLinearDamper between p_a on body_a and p_b on body_b (body frames; −1 the ground).
struct TwinSpring {
  int body_a = -1, body_b = -1;
  Vec3 p_a = Vec3::Zero(), p_b = Vec3::Zero();
  double stiffness = 0, rest_length = 0, damping = 0;
};

struct TwinModel {
  std::vector<TwinBody> bodies;  // parents first
  std::vector<int> theta_body;   // θ̇ index (a rate) -> body
  int n_theta_q = 0;             // θ's entries (Σ nq; n_theta() without quaternions)
  SpMatX C;                      // θ = C q + θ0 (sparse: the identity is n entries, not n²)
  VecX theta0;
  Vec3 gravity = Vec3::Zero();
  struct Load {
    int body;
    Vec3 point, force, torque;  // point in the body frame; force, torque in the world frame
  };
  std::vector<Load> loads;
  // The closed-loop form (nonlinear coupling laws or rods): q_k = θ_{coordinate_theta[k]}, the
  // other joints follow `laws` (dependency order); C and θ0 are then unused.
  std::vector<int> coordinate_theta;
  std::vector<TwinLaw> laws;
  std::vector<TwinRod> rods;
  // Loops closed by constraints (disabled but where SimbodyTwin::loop_dynamics and a simulate
  // with close_loops(true) enable them: every other entry point sees the tree) and springs.
  std::vector<TwinConstraint> constraints;
  std::vector<TwinSpring> springs;
  // The flexible bars' damping −D θ̇ on one-rate joints (Model::rate_damping, whose q̇ is θ̇
  // there): entries (rate a, rate b, D_ab).
  struct RateDamping {
    int a = -1, b = -1;
    double d = 0;
  };
  std::vector<RateDamping> rate_damping;
  bool closed_loop() const { return !laws.empty() || !rods.empty(); }
  int n() const { return static_cast<int>(closed_loop() ? coordinate_theta.size() : C.cols()); }
  int n_theta() const { return static_cast<int>(theta_body.size()); }
  // θ's index of rate j (θ̇ index) on a joint with nq = nv.
  int theta_of_rate(int j) const;
  // femdyn's q lists the joints of the coordinates in order (coordinate k's joint has rate
  // own_rate[k]), each with its nq entries: each body's first entry in q (-1 for a body that
  // owns no coordinate), and n_q in `n_q`.
  std::vector<int> configuration_layout(const std::vector<int>& own_rate, int& n_q) const;
};

// A joint type's coordinates nq (4 for a ball's quaternion, 7 for a free joint).
int coordinates_of(TwinBody::Joint type);

// Simbody's equations reduced to q: M = Cᵀ M_θ C, h = Cᵀ h_θ(C q̇), Q = Cᵀ Q_θ + τ.
struct TwinEquations {
  MatX M;   // n x n; empty when asked for products only (SimbodyTwin::equations with V)
  MatX MV;  // M V for the V asked for (n x p), else empty
  VecX h, Q, qdd;
  // Closed loop: Simbody's constraint errors at the state set from q, q̇ (max |qerr|, |uerr|:
  // m and m/s for a rod's ball, rad and rad/s for a coupler); 0 otherwise.
  double loop_position_error = 0, loop_velocity_error = 0;
};

// A frame fixed on a body (femdyn's Model::frames): its axes R_BF and origin p_BF in the body
// frame, which is the twin's MobilizedBody frame too (X_BM carries the mobilizer's axes).
struct TwinFrame {
  int body = -1;
  Mat3 R_BF = Mat3::Identity();
  Vec3 p_BF = Vec3::Zero();
};

// Simbody's constrained forward dynamics with the loop constraints enabled (loop_dynamics).
struct TwinLoopDynamics {
  VecX qdd;               // q̈ of the coordinates
  VecX constraint_force;  // the generalized constraint forces on q: −Cᵀ Pᵀ Gᵀ λ (Simbody's
                          // M u̇ + Gᵀ λ = f), femdyn's Φ_qᵀ λ
  double position_error = 0, velocity_error = 0;  // max |qerr|, |uerr| at the state
};

// Simbody's kinematics at (q, q̇) (SimbodyTwin::kinematics), in femdyn's order and axes:
// linear before angular, world axes, moments about the mechanism's centre of mass.
struct TwinKinematics {
  std::vector<Mat3> R;  // per frame: R_GF = R_GB R_BF   (findFrameTransformInGround)
  std::vector<Vec3> p;  //            p_GF = p_GB + R_GB p_BF
  MatX velocity;        // 6 × frames: (v, ω) of each frame's origin (findFrameVelocityInGround)
  MatX acceleration;    // 6 × frames: (a, α) under Simbody's own forward dynamics at τ
  MatX J;               // 6·frames × n when asked: frame f's rows 6f…6f+5, ∂(v, ω)/∂q̇
  double mass = 0;      // calcSystemMass
  Vec3 com = Vec3::Zero();                  // calcSystemMassCenterLocationInGround
  Mat3 inertia_com = Mat3::Zero();          // calcSystemCentralInertiaInGround
  Vec3 com_velocity = Vec3::Zero();         // ...MassCenterVelocityInGround
  Vec3 com_acceleration = Vec3::Zero();     // ...MassCenterAccelerationInGround
  Eigen::Matrix<double, 6, 1> momentum =    // calcSystemCentralMomentum, reordered:
      Eigen::Matrix<double, 6, 1>::Zero();  //   (P, L_G)
};

struct TwinSample {
  double t = 0;
  VecX theta, theta_dot;  // all joint coordinates θ (n_theta_q) and rates (n_theta), femdyn's
  double energy = 0;      // Simbody's kinetic + potential energy
};

// Simbody's error-controlled integrators, for trajectories (SimbodyTwin::simulate) and the
// work-precision study. Each is used in its default error-controlled (variable-step) mode at
// the accuracy asked for, never with a fixed step; how the samples are taken is TwinSampling.
enum class SimbodyIntegrator {
  RungeKuttaMerson,    // 4th order, embedded error estimate (the twin's default)
  RungeKutta3,         // 3rd order, embedded 2nd-order estimate
  RungeKuttaFeldberg,  // 5th order (Fehlberg), embedded error estimate
  Verlet,              // velocity Verlet, variable step (not symplectic in this mode)
  SemiExplicitEuler2,  // 1st-order semi-explicit (symplectic) Euler, step-doubling estimate
  CPodes               // implicit variable-order multistep (SUNDIALS CVODES): BDF, Newton
};

// Exactly the enumerator's name, e.g. "RungeKuttaMerson".
const char* simbody_integrator_name(SimbodyIntegrator which);

// The integrators that can run in this process, in enum order: Simbody 3.7 has all six, but
// CPodes is left out where another SUNDIALS in the process shadows Simbody's bundled copy of
// it (femdyn links its own statically, symbols hidden, so it does not); simulate() refuses it
// there.
std::vector<SimbodyIntegrator> simbody_integrators();

// How a trajectory is sampled:
//   StepToEach: by TimeStepper::stepTo(t), which passes t to the integrator as a scheduled event
//     time too, so a step ends exactly at every sample time (the samples cap the step at their
//     spacing) and each sample is a step's own state.
//   Interpolate: by Integrator::stepTo(t) with no scheduled event and the final time set to the
//     last sample (as femdyn's adaptive integrators, which never step past t_stop), so the
//     integrator steps freely and a sample inside a step is interpolated: a cubic Hermite
//     interpolant of the step's ends for the Runge–Kutta and Verlet integrators (projected back
//     onto the constraints), CPODES' own Nordsieck interpolation for CPodes (which interpolates
//     in either mode: CPODES in its normal mode steps past the time asked and interpolates back).
enum class TwinSampling { StepToEach, Interpolate };

// What one SimbodyTwin::simulate run cost, from Simbody's own counters.
struct TwinRunStats {
  long steps = 0;                 // Integrator::getNumStepsTaken()
  long attempts = 0;              // getNumStepsAttempted()
  long realizations = 0;          // getNumRealizations(): Simbody's right-hand-side evaluations
  long error_test_failures = 0;   // getNumErrorTestFailures()
  long convergence_failures = 0;  // getNumConvergenceTestFailures() (iterative methods; else 0)
  double wall_time = 0;           // s in initialize and stepTo only (not samples, energy)
  bool ok = true;
  bool out_of_time = false;  // stopped by TwinRunLimits::wall_time (then ok = false)
  std::string failure;       // one line: why the run stopped early, if it did (then ok = false)
};

struct TwinRun {
  std::vector<TwinSample> samples;  // those reached (all of `times` when stats.ok)
  TwinRunStats stats;
};

// Bounds on a run (validate's budget): past `wall_time` seconds it stops (stats.ok = false, the
// reason in stats.failure), looked at every few steps; `on_sample(t)` is called after each
// sample. A run with no bound steps exactly as before (the bound only makes Simbody return to
// the caller between steps, which changes none of them).
struct TwinRunLimits {
  double wall_time = 0;  // s; 0: none
  std::function<void(double t)> on_sample;
};

class SimbodyTwin {
 public:
  explicit SimbodyTwin(TwinModel model);
  ~SimbodyTwin();
  SimbodyTwin(const SimbodyTwin&) = delete;
  SimbodyTwin& operator=(const SimbodyTwin&) = delete;

  // With V (n x p): MV = M V and M left empty. Without a coupling (C = I, θ0 = 0) M is never
  // formed: Simbody's O(n) operator multiplyByM on each column; a coupled tree (which solves
  // M q̈ = Q − h with it) and a closed loop (which has no such operator) form M and multiply.
  // Without V: M, and MV empty.
  TwinEquations equations(const VecX& q, const VecX& qd, const VecX& tau, const MatX* V = nullptr);
  VecX inverse_dynamics(const VecX& q, const VecX& qd, const VecX& qdd);

  // The frames' poses, velocities and accelerations and the mechanism's mass, centre of mass
  // and central momentum at (q, q̇), the accelerations those of Simbody's forward dynamics
  // under its forces and τ on the coordinates: the state realized to Acceleration with τ as
  // discrete mobility forces (constrained: the closed loop's and the couplers'), or, where the
  // coupling cannot be posed as couplers, u̇ from the reduced equations' q̈ and
  // calcBodyAccelerationFromUDot. With `jacobian`, J's columns: the frames' velocities at
  // q̇ = e_k (multiplyByFrameJacobian). Throws femdyn::Error (one line) where Simbody fails.
  TwinKinematics kinematics(const VecX& q, const VecX& qd, const VecX& tau,
                            const std::vector<TwinFrame>& frames, bool jacobian = false);

  // The model's loop constraints (TwinModel::constraints): q̈ and the constraint forces at
  // (q, q̇) under τ with them enabled (twin_constraints.cpp). The state should satisfy them
  // (femdyn's assemble_state). Throws femdyn::Error (one line) where Simbody fails or the twin
  // cannot pose them (a closed-loop twin; a coupling not posed as coordinate couplers).
  TwinLoopDynamics loop_dynamics(const VecX& q, const VecX& qd, const VecX& tau);
  // Whether simulate() runs with the loop constraints enabled (false: the tree).
  void close_loops(bool closed);

  // Passive motion (τ = 0) from (q0, q̇0) by RungeKuttaMersonIntegrator at `accuracy`, sampled
  // at `times`. Empty with `why_not` set if the coupling cannot be posed as coordinate
  // couplers (each q_k must drive some θ_j = q_k directly). Throws std::runtime_error (one
  // line) if the integration fails.
  bool can_simulate(std::string* why_not = nullptr) const;
  std::vector<TwinSample> simulate(const VecX& q0, const VecX& qd0,
                                   const std::vector<double>& times, double accuracy);
  // The same by `which`, sampled as `sampling` says, with its statistics and wall time. Never
  // throws for a failed integration: stats.ok = false, stats.failure says why and `samples`
  // holds those reached (none, with the reason, if the coupling cannot be posed as coordinate
  // couplers).
  TwinRun simulate(const VecX& q0, const VecX& qd0, const std::vector<double>& times,
                   double accuracy, SimbodyIntegrator which,
                   TwinSampling sampling = TwinSampling::StepToEach,
                   const TwinRunLimits& limits = {});

  // Timing entry points (validation/benchmark.cpp, femdyn bench): Simbody's own work only,
  // on buffers allocated by the first call. Each sets θ = C q + θ0, θ̇ = C q̇ (a plain loop)
  // and realizes the stage it needs; nothing is reduced to q or converted to Eigen, and the
  // results stay inside the twin. With a coupling (n < nθ) Simbody's M, h and τ are those of the
  // tree of nθ joints (the reduction by C is not timed).
  //   mass_and_bias: realize Dynamics (forces), calcM, and the residual with the applied forces
  //                  and θ̈ = 0 (that is h − Q), the counterpart of femdyn's evaluate();
  //   bias:          realize Velocity, the residual with no force and θ̈ = 0 (h);
  //   forward:       realize Dynamics, τ_k added on the joint q_k drives directly
  //                  (independent_theta), then calcAccelerationIgnoringConstraints (O(n)
  //                  articulated body), or calcAcceleration when the coupling is posed as
  //                  coordinate couplers (the coupled motion, as femdyn's);
  //   inverse:       realize Dynamics, the residual with the applied forces and θ̈ = C q̈;
  //   mass:          θ̇ = 0, realize Position, calcM (M_θ alone);
  //   gravity:       θ̇ = 0, realize Dynamics, the residual with the applied forces and θ̈ = 0
  //                  (that is −Q at rest: gravity, loads, springs);
  //   tensor:        realize Position once, then n + n(n+1)/2 velocity-stage residuals with no
  //                  force and θ̈ = 0 at θ̇ = C e_b and θ̇ = C (e_b + e_c), b ≤ c, combined by
  //                  polarization into D_sym(·, b, c) = (h(e_b + e_c) − h(e_b) − h(e_c)) / 2,
  //                  the part of D symmetric in (b, c) (Simbody forms no such tensor);
  //   constrained:   the loop constraints enabled (TwinModel::constraints), τ_k as discrete
  //                  mobility forces on the joint q_k drives directly, realize Acceleration:
  //                  Simbody's constrained forward dynamics (its constraint solve), the
  //                  counterpart of femdyn's constrained_forward_dynamics at ω = 0. It works on
  //                  a state of its own (a copy of the twin's made by the first call, the loops
  //                  enabled there), so the other entry points keep the tree and neither side
  //                  pays for Simbody's re-realization when constraints are switched; the state
  //                  should satisfy the constraints (femdyn's assemble_state). Throws
  //                  femdyn::Error where the twin cannot pose them (as loop_dynamics).
  // (femdyn bench, cli/bench.cpp, times all eight; constrained on models with constraints.)
  void time_mass_and_bias(const VecX& q, const VecX& qd);
  void time_bias(const VecX& q, const VecX& qd);
  void time_forward(const VecX& q, const VecX& qd, const VecX& tau);
  void time_inverse(const VecX& q, const VecX& qd, const VecX& qdd);
  void time_mass(const VecX& q);
  void time_gravity(const VecX& q);
  void time_tensor(const VecX& q);
  void time_constrained(const VecX& q, const VecX& qd, const VecX& tau);

 private:
  // The same without the guard that turns SimTK's exceptions into one line.
  TwinEquations equations_unguarded(const VecX& q, const VecX& qd, const VecX& tau, const MatX* V);
  VecX inverse_dynamics_unguarded(const VecX& q, const VecX& qd, const VecX& qdd);
  TwinEquations closed_loop_equations(const VecX& tau);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// θ_j that carries q_k directly (row j of C is e_k and θ0_j = 0), or -1.
int independent_theta(const TwinModel& model, int k);
// The same for every k at once, in O(nnz(C) + nθ).
std::vector<int> independent_thetas(const TwinModel& model);

}  // namespace femdyn::validation
