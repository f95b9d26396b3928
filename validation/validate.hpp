// femdyn against its Simbody twin: pointwise at seeded random states, and along a passive
// trajectory. docs/validation.md describes the method and the tolerance policy.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/model/errors.hpp"
#include "core/model/model.hpp"
#include "core/workspace/memory.hpp"  // the memory limit, shared with every command
#include "validation/twin.hpp"

namespace femdyn::validation {

// The longest trajectory compared (s), for `femdyn validate --t-end` and femdyn.validate's
// t_end alike: a bound on the check's run time. femdyn's RK4 run starts at a 1 ms step
// (rk4_step) and is refined only within a budget of max_rk4_steps (1e5) steps, which a
// trajectory of 100 s spends at its first halving.
inline constexpr double kMaxTrajectoryTime = 100;

// Bounded work (docs/validation.md, "Bounded work"). Each validation is estimated before any
// state is compared, from n and a timed probe, and refused beyond a budget of time
// (ValidationOptions::budget, `femdyn validate --budget`) or of memory (half the memory
// available, /proc/meminfo's MemAvailable, unless ValidationOptions::memory_limit says
// otherwise). Up to kDenseMassLimit coordinates M^s is compared entry by entry (Simbody's calcM,
// n² numbers); beyond, by its products M^s V with kMassProducts seeded random vectors
// (Simbody's O(n) multiplyByM), so that no n x n matrix but femdyn's own M^s is formed.
inline constexpr double kDefaultBudget = 120;  // s
inline constexpr int kDenseMassLimit = 1000;
inline constexpr int kMassProducts = 4;
// The kinematics for control (docs/validation.md, "Frames, centre of mass, momentum") are compared
// up to kKinematicsLimit coordinates (femdyn's frame Jacobians are 6 × n each, its body
// Jacobians 3·bodies × n), the frame Jacobians J column by column up to kFrameJacobianLimit
// (Simbody's velocity at q̇ = e_k, n operator calls a state).
inline constexpr int kKinematicsLimit = kDenseMassLimit;
inline constexpr int kFrameJacobianLimit = 300;

// The default pointwise tolerance, relative: max(1e-10, ε·d²) for a tree whose longest path
// from the world holds d bodies. The two engines compute the same physics, so they differ by
// round-off only; each quantity at a joint is a sum over the d bodies beyond it of terms whose
// size grows along the path, so its relative round-off grows like ε·d² (measured on random
// chains: 0.03 ε·d² at 1000 and 10,000 bodies). Below 670 bodies deep this is the fixed 1e-10.
double pointwise_tolerance(const Model& m);

struct ValidationOptions {
  int states = 20;  // K seeded random states
  unsigned seed = 1;
  double qd_scale = 2;       // q̇ uniform in ±qd_scale (rad/s, m/s)
  double tau_scale = 1;      // τ uniform in ±tau_scale (N·m, N)
  double qdd_scale = 5;      // q̈ for inverse dynamics, uniform in ±qdd_scale
  double tolerance = 0;      // relative, on M^s, h, Q, q̈, τ; 0: pointwise_tolerance(model) below
  double t_end = 0.25;       // trajectory length (s); 0 = no trajectory
  int samples = 50;          // trajectory samples compared
  double rk4_step = 1e-3;    // femdyn's first RK4 step (s), halved until the error estimate
  double rk4_target = 1e-9;  // (relative to the state's size) is below this,
  double max_rk4_steps = 1e5;        // or the finer run would take more steps than this
  double resolved_tolerance = 1e-6;  // the trajectory check fails as unresolved above this
  double simbody_accuracy = 1e-10;
  double budget = kDefaultBudget;  // s: estimated beyond it, refused; the trajectory's
                                   // refinement and Simbody's runs stop at it
  double memory_limit = 0;         // bytes; 0: half of the available memory
  // Called now and then with the work done and the work planned, in estimated seconds (for a
  // progress line); from the calling thread.
  std::function<void(double done, double total)> progress;
};

// What a validation will cost, estimated before any state is compared (Validator).
struct WorkEstimate {
  int n = 0, states = 0;
  bool dense_mass = true;   // M^s entry by entry (n <= kDenseMassLimit), else by products
  double setup = 0;         // s spent building the twin and probing (already spent)
  double per_state = 0;     // s: one pointwise state, both engines
  double pointwise = 0;     // s: the K states
  double trajectory = 0;    // s: the trajectory as usually refined (docs/validation.md)
  double bytes = 0;         // peak memory of the check beyond the loaded model (B)
  double budget = 0;        // s
  double memory_limit = 0;  // B; infinite where the available memory is unknown
  bool at_least = false;    // Simbody's probe ran out of time: the estimate is a lower bound
  double seconds() const { return pointwise + trajectory; }
  bool within() const { return seconds() <= budget && bytes <= memory_limit; }
};

// Refused up front: what() is the one line Validator::refusal gives.
class OverBudget : public Error {
 public:
  using Error::Error;
};

// One compared quantity: max over the states of ‖x_femdyn − x_simbody‖∞ and of that divided by
// ‖x_simbody‖∞ (the absolute error when the Simbody quantity is zero); for the centre of mass
// and the momentum, by the larger of that and the size of their parts (docs/validation.md).
struct QuantityError {
  std::string name;  // "M", "h", "Q", "qdd", "tau", "loop", "frame pose", …, "momentum"
  double max_abs = 0, max_rel = 0, tolerance = 0;
  bool pass() const { return max_rel <= tolerance; }
};

struct TrajectoryReport {
  bool run = false;
  bool constrained = false;  // the closed mechanism's (a model with loop constraints)
  std::string skipped;       // why not run, if not
  double t_end = 0;
  double max_state_error = 0;  // max over samples of ‖(θ, θ̇)_femdyn − (θ, θ̇)_simbody‖∞
  double rk4_step = 0;         // step of the femdyn run compared
  double rk4_error_estimate = 0;      // Richardson estimate of femdyn's own RK4 error (dt vs dt/2)
  double simbody_error_estimate = 0;  // Simbody at its accuracy against 100x tighter
  bool resolved = true;               // both estimates small enough for the comparison to mean much
  double tolerance = 0;
  double energy_change_femdyn = 0, energy_change_simbody = 0;  // max |E(t) − E(0)|
  std::vector<double> t, error;                                // the state error over time
  std::vector<double> energy_femdyn,
      energy_simbody;  // E(t) of both runs (J; each with its own zero)
  // Why the comparison could not be made within the budget (Simbody's runs stopped): it fails.
  std::string stopped;
  // Why femdyn's RK4 step was not halved down to its target, if it was not ("not halved beyond
  // dt = …": the budget, the step limit; "not halved further": Simbody's own error already too
  // large for the comparison to resolve the motion).
  std::string refinement;
  bool pass() const {
    return stopped.empty() && (!run || (resolved && max_state_error <= tolerance));
  }
};

struct ValidationReport {
  std::string model;
  int n = 0, states = 0;
  std::vector<QuantityError> quantities;
  TrajectoryReport trajectory;
  std::vector<std::string> notes;  // e.g. approximations the model makes on purpose
  std::string failure;             // why no comparison could be made (then it fails)
  // The failure is only what Simbody cannot represent (a massless body with a rotary inertia):
  // the model is not compared, neither passed nor failed (`femdyn validate` exits 3).
  bool not_comparable = false;
  bool dense_mass = true;  // "M" entry by entry; else ‖ΔM^s V‖∞ / ‖M^s V‖∞
  WorkEstimate estimate;
  double wall_time = 0;  // s: the whole validation, the twin and the probes included
  bool pass() const;
};

// One validation in two steps: the constructor builds the Simbody twin and times a probe
// (femdyn's forward and inverse dynamics, its evaluate() up to 3000 coordinates, its energy;
// Simbody's equations and inverse dynamics, and the first twentieth of its trajectory, within
// budget / 83 s), then estimate() says what run() would cost and refusal() whether that is
// beyond the budget. The model must outlive the Validator; run() is called once.
class Validator {
 public:
  Validator(const Model& model, ValidationOptions options);
  ~Validator();
  Validator(const Validator&) = delete;
  Validator& operator=(const Validator&) = delete;

  const WorkEstimate& estimate() const;
  // "" within the budget and the memory limit, else one line naming `label` (the model file),
  // n, the estimated time and memory, the budget, and how to proceed.
  std::string refusal(const std::string& label) const;
  ValidationReport run();  // the comparison (whatever the estimate)
  void set_progress(std::function<void(double done, double total)> progress);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Validator(model, options).run(), or OverBudget (naming model.where) beyond the budget.
ValidationReport validate(const Model& model, const ValidationOptions& options = {});

// For a model read from a URDF file: femdyn's M^s, h, Q against an independent Simbody model
// built straight from the XML (urdf_twin.hpp), at the same seeded states. Returns the quantity
// "import" (the largest of the three relative errors); `failure` is set if the twin cannot be
// built. `balance_inertia`: the model was loaded with it (the twin balances the same bodies).
QuantityError validate_urdf_import(const Model& model, const std::string& urdf_path,
                                   const ValidationOptions& options, std::string& failure,
                                   bool balance_inertia = false);

// For a model read from an MJCF file, with the MuJoCo peer built (FEMDYN_WITH_MUJOCO): femdyn's
// M^s, τ and q̈ against MuJoCo's own compile of the file (validation/mujoco_peer.hpp) at the
// same seeded states, femdyn's Coulomb friction handed to MuJoCo as an applied force (its
// frictionloss is a constraint, off in the peer). Returns the quantity "mujoco"; or nullopt with
// `why` when it cannot be compared: MuJoCo cannot read the file (Debian's 2.2 knows no MuJoCo 3
// element), or femdyn holds an <equality joint> as a coupling (fewer coordinates than dofs).
// `mesh_masses`: the number of mesh geoms that gave mass (MuJoCo holds meshes in single
// precision: the tolerance is then 1e-6, said in `why`); `full_inertias`, the <inertial
// fullinertia> read (MuJoCo's compiler diagonalises each by an iteration that stops early, about
// 1e-8 relative: the tolerance is then 1e-7, said in `why`). A model with couplings is compared
// through them (validation/validate_mjcf.cpp). The peer weighs every mesh by its exact
// solid (exactmeshinertia; MuJoCo 2.2's legacy takes the equivalent box's volume).
std::optional<QuantityError> validate_mjcf_import(const Model& model, const std::string& path,
                                                  int mesh_masses, int full_inertias,
                                                  const ValidationOptions& options,
                                                  std::string& why);

// ‖x_femdyn − x_reference‖∞ / max(‖x_reference‖∞, floor) into e's largest errors (the absolute
// error when both are 0). The floor is the size of what the quantity is made of.
void accumulate(QuantityError& e, const MatX& femdyn, const MatX& reference, double floor = 0);
// h's floor: ‖M^s‖∞ ‖q̇‖∞² (h cancels to round-off on some mechanisms).
double bias_floor(const MatX& Ms, const VecX& qd);

// What the Simbody twin reads of a model; each body's mass properties are the sum of its
// elements'. Used by validate() and femdyn_bench.
TwinModel twin_model(const Model& model);

}  // namespace femdyn::validation
