// What the files of the validator share (validation/validate.hpp, Validator): Validator::Impl,
// the state of one validation, and the clock it is timed by. Its parts live in
//   validate.cpp             the front door: Validator, validate()
//   validate_cost.cpp        the twin built, the cost probed, and the refusal beyond the budget
//   validate_points.cpp      the pointwise comparison at random states (M, h, Q, q̈, τ, loops,
//                            frames, centre of mass and momentum)
//   validate_trajectory.cpp  the trajectory, refined until both engines' errors are known
//   twin_model.cpp           the Model as the twin's TwinModel
#pragma once
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include "core/kinematics/frames.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/model/model.hpp"
#include "core/workspace/workspace.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The wall time of one call of f: the first call alone when it is slow (over 20 ms), else the
// mean of up to five more (the first warms the buffers up).
template <class F>
double timed(F&& f) {
  auto t0 = Clock::now();
  f();
  const double first = seconds_since(t0);
  if (first > 0.02) return first;
  int calls = 0;
  t0 = Clock::now();
  do {
    f();
    ++calls;
  } while (calls < 5 && seconds_since(t0) < 0.02);
  return seconds_since(t0) / calls;
}

// Simbody's run at 100x the accuracy takes 100^(1/4) = 3.2 times as many steps of its
// 4th-order method (measured: 3.0 to 3.1).
inline const double kTightRatio = std::pow(100.0, 0.25);

struct Validator::Impl {
  const Model& m;
  ValidationOptions o;
  Clock::time_point start = Clock::now();
  ValidationReport r;  // notes and failures found while building the twin
  TwinModel tm;
  std::unique_ptr<SimbodyTwin> twin;
  Workspace ws;
  MatX V;  // products: the seeded random vectors M^s is multiplied by
  // The frames and the mechanism (up to kKinematicsLimit coordinates), and femdyn's buffers.
  bool kinematics = false, frame_jacobian = false;
  std::vector<TwinFrame> frames;
  FrameKinematics fk;
  MomentumKinematics mk;
  WorkEstimate estimate;
  // Probes (s): femdyn's forward dynamics and its energy at a state.
  double t_fd = 0, t_energy = 0;
  double simbody_cost = 0;  // s: Simbody's two trajectory runs, as estimated

  Impl(const Model& model, ValidationOptions options);

  // validate_cost.cpp
  bool build();                 // the twin, or r.failure saying why there is none
  bool sums_to_rigid_bodies();  // each body's elements a rigid body, else r.failure says not
  void probe();                 // the costs, from one state of each kind of work
  double probe_state();         // s: one state's comparison
  double probe_trajectory();    // s: the trajectory's runs
  double memory_bytes() const;  // what run() will hold

  // validate_points.cpp
  // femdyn's frames and mechanism at (q, v), stacked as the twin's (TwinKinematics): each
  // frame's pose, velocity J v and acceleration J v̇ + J̇v (with v̇ = `v_dot`, the forward
  // dynamics'), J when compared, and the mechanism in `mk`.
  struct StackedFrames {
    MatX R, p, velocity, acceleration, J;
  } femdyn_frames;
  void femdyn_kinematics(const VecX& q, const VecX& v, const VecX& v_dot);
  // The compared kinematics (run() adds them after M, h, Q, q̈, τ and the loop).
  struct KinematicErrors {
    QuantityError *pose, *velocity, *acceleration, *jacobian, *com, *com_velocity,
        *com_acceleration, *momentum;
  };
  KinematicErrors add_kinematic_quantities(double tol);
  void compare_kinematics(const TwinKinematics& s, const VecX& v, const VecX& v_dot,
                          bool accelerations, KinematicErrors& e);
  // One random state's M, h, Q, q̈, τ, loop and kinematics; the largest cond(M^s) in `cond`.
  void compare_state(const VecX& q, const VecX& qd, const VecX& tau, const VecX& qdd,
                     KinematicErrors& ek, double& cond);
  void tolerate_conditioning(double cond);
  ValidationReport run();

  // validate_trajectory.cpp: the trajectory from (q0, q̇0), within what is left of the budget
  TrajectoryReport trajectory(const VecX& q0, const VecX& qd0, Clock::time_point deadline,
                              const std::function<void(double)>& progress);
};

}  // namespace femdyn::validation
