// What the files of the Simbody twin share (twin.hpp): SimbodyTwin::Impl, the Simbody system
// built from a TwinModel and the maps between femdyn's θ, q and Simbody's state. Includes
// Simbody: read only by the twin's own files, compiled like twin.cpp (C++17, without NDEBUG).
//   twin_mobilizers.cpp  femdyn bodies and joints as mobilized bodies, forces, the system
//   twin_couplings.cpp   couplings θ = C q + θ0 as coordinate couplers
//   twin_loops.cpp       the closed loops (laws and rods)
//   twin_constraints.cpp the model's loop constraints and two-point springs
//   twin_state.cpp       femdyn q, q̇ <-> Simbody's state; Cᵀ and C on Simbody's u layout
//   twin.cpp             the equations, inverse dynamics and the timing entry points
//   twin_kinematics.cpp  frames, centre of mass and momentum (SimbodyTwin::kinematics)
//   twin_simulate.cpp    Simbody's integrators and trajectories
#pragma once
#include <Simbody.h>

#include <string>
#include <vector>

#include "validation/twin.hpp"

namespace femdyn::validation {

// A message on one line: its lines joined by spaces, without SimTK's "SimTK Exception thrown
// at file:line:" headers. (The first line alone would often be such a header, or
// "Integrator step failed at time 0 apparently because:", with the cause on the next lines.)
std::string one_line(const std::string& text);

constexpr bool kTiming = false;  // set_state's fit_rods in the timing entry points

struct SimbodyTwin::Impl {
  const TwinModel model;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  // τ as mobility forces while kinematics() realizes Acceleration; zero at every other time.
  SimTK::Force::DiscreteForces tau_forces{forces, matter};
  std::vector<SimTK::MobilizedBody> mobod;  // per femdyn body
  std::vector<SimTK::MobilizedBody> rods;   // closed loop: per TwinModel::rods
  // Per TwinModel::constraints, disabled by default; enabled while `loops_enabled`.
  std::vector<SimTK::Constraint> loop_constraints;
  bool loops_enabled = false;
  bool simulate_closed = false;  // SimbodyTwin::close_loops
  // Enables (disables) the loop constraints in `state` (its stage falls to Model on a change).
  void enable_loops(bool on);
  VecX loop_theta, loop_theta_dot;  // closed loop: θ = g(q), θ̇ = G q̇
  std::vector<int> theta_q;         // θ index (n_theta_q) -> Simbody q index
  std::vector<int> theta_u;         // θ̇ index (n_theta) -> Simbody u index
  // A ball's or free joint's triple of rates: Simbody's u there is R_FM times femdyn's (B's
  // axes to F's), R_FM from the quaternion at Simbody q index `quat`.
  struct Rotated {
    int quat = -1;
    int rate = -1;             // its first θ̇ index
    bool free_linear = false;  // a free joint's linear triple (its ω at rate + 3)
  };
  std::vector<Rotated> rotated;
  std::vector<Eigen::Matrix3d> rot;  // R_FM of each, at the state set_state set
  SimTK::Vector pdot_v;              // Ṗ v on Simbody's u layout at that state (0 without free)
  std::vector<int> independent;      // q index -> θ index, -1 if none
  bool couplers = true;
  Eigen::SparseMatrix<double, Eigen::RowMajor> C_rows;  // C by rows: θ_j = Σ C_jk q_k + θ0_j
  // With a ball or free joint, θ (n_theta_q) = C_q q + θ0_q for q of the coordinate joints'
  // entries in turn (configuration_coupling(): C's rows on q's layout, a quaternion copied).
  Eigen::SparseMatrix<double, Eigen::RowMajor> C_configuration;
  VecX theta0_configuration;
  void configuration_coupling();
  SimTK::State state;
  SimTK::Matrix M_theta;
  SimTK::Vector zero_mobility, residual, mobility, udot;
  SimTK::Vector_<SimTK::SpatialVec> zero_body, A_GB;

  explicit Impl(TwinModel tm);

  // One femdyn body as a mobilized body with its mobilizer, spring and damper.
  void add_body(const TwinBody& j);

  // Gravity, loads and couplers, then the realized state.
  void finish_system();

  // Couplings θ_j = Σ_k C_jk q_k + θ0_j as constraints among the mobilities, for trajectories.
  void add_linear_couplers();

  // The realized state and the index maps.
  void finish_state();

  VecX reduce(const SimTK::Vector& f_theta) const;  // Cᵀ Pᵀ f_u

  // R_FM of each rotated triple from Simbody's q.
  std::vector<Eigen::Matrix3d> rotations(const SimTK::Vector& sq) const;
  // Pᵀ f_u (femdyn's θ̇ layout) and P x (Simbody's u layout), with these rotations.
  VecX gather(const SimTK::Vector& f_u, const std::vector<Eigen::Matrix3d>& R) const;
  SimTK::Vector scatter(const VecX& x, const std::vector<Eigen::Matrix3d>& R) const;

  // Buffers of the timing entry points (time_*).
  SimTK::Vector bench_applied, bench_udot, bench_theta_ddot, bench_out;
  SimTK::Vector_<SimTK::SpatialVec> bench_A_GB;
  VecX bench_rest;                  // q̇ = 0
  SimTK::Matrix bench_h1, bench_D;  // h(e_b) by columns; D_sym(·, b, c) in column b n + c
  // time_constrained: its own state with the loop constraints enabled (made by the first call,
  // swapped with `state` for each call), and τ on Simbody's u layout.
  SimTK::State bench_loop_state;
  SimTK::Vector bench_tau;
  bool bench_loops_ready = false;
  void prepare_loop_timing();

  const VecX& rest();  // q̇ = 0, sized by the first call

  // θ̇ = C (e_b + e_c) (c < 0: C e_b) written into the state; invalidates Velocity and above
  // only, so the realized Position stage stays.
  void set_unit_rates(int b, int c);

  // Sets θ = C q + θ0, θ̇ = C q̇ (without temporaries: the timing entry points use it too) and
  // realizes `stage`. Closed loop: θ = g(q), θ̇ = G q̇, and each rod fitted between its ends
  // unless `fit_rods` is false (the timing entry points: a rod left as the last call set it
  // changes none of the work Simbody does, only its constraint errors).
  void set_state(const VecX& q, const VecX& qd, SimTK::Stage stage, bool fit_rods = true);

  // θ, θ̇ and the energy of an integrator's state.
  TwinSample sample(const SimTK::State& st) const;

  // Closed loop: q̈ of the coordinates by Simbody's constrained forward dynamics under these
  // applied forces.
  VecX constrained_qdd(const SimTK::Vector& applied, const SimTK::Vector_<SimTK::SpatialVec>& body);
  // Closed loop: a force on the coordinates as mobility forces (P f on their joints' rates).
  SimTK::Vector coordinate_forces(const VecX& f) const;

  // Closed loop: M^s as the inverse of q̈'s response to a unit force on each coordinate,
  // (M^s)⁻¹ e_k = q̈(e_k) − q̈(0), with a0 = q̈(no force).
  MatX constrained_mass(const VecX& a0);

  SimTK::Vector expand(const VecX& x) const;  // P C x on Simbody's u layout

  // τ on the coordinates as mobility forces on the joints each drives directly: P f_θ with
  // (f_θ)_independent[k] = τ_k, so that Cᵀ f_θ = τ (every independent[k] >= 0).
  SimTK::Vector independent_forces(const VecX& tau) const;

  // SimbodyTwin::kinematics; `qdd` is Simbody's q̈ from the reduced equations where the coupling
  // cannot be posed as couplers (!couplers), else unused.
  TwinKinematics kinematics(const VecX& q, const VecX& qd, const VecX& tau, const VecX& qdd,
                            const std::vector<TwinFrame>& frames, bool jacobian);
  // Its parts, at the state kinematics() set: the frames' Jacobian J (6 per frame, linear rows
  // first, n columns), and the frames' and the mass centre's accelerations.
  MatX frame_jacobians(const VecX& q, const std::vector<TwinFrame>& frames,
                       const std::vector<SimTK::Transform>& X_BF) const;
  void accelerations(const VecX& tau, const VecX& qdd, const std::vector<TwinFrame>& frames,
                     const std::vector<SimTK::Transform>& X_BF, TwinKinematics& out);
};

}  // namespace femdyn::validation
