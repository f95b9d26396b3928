// The stability suite (femdyn stress, docs/stability.md): one generated case is a model plus a
// scenario (initial state, time span, a fixed step), diagnosed as
//   - cond(M^s) over the reference trajectory, symmetry, positive definiteness;
//   - the reference motion: Dormand–Prince at rtol 1e-10, or BDF at 1e-10 when Dormand–Prince
//     gives up (a stiff case), and its energy balance |E − E0 − W| relative to the energy;
//   - for rk4 and euler the largest stable step, by bisection of real runs from the initial
//     state: a step is stable when a run of at least kMinSteps steps and kPeriods periods of
//     the stiffest mode (2π/|λ|) ends without diverging or failing (sim/divergence.hpp), so
//     a step longer than the scenario still gets its steps; beside it the linear theory's
//     limit at the initial state (sim/stability.hpp); for every integrator the error at the
//     scenario's step (rk4, euler) or at rtol 1e-6 (dopri, bdf);
//   - agreement with Simbody's twin (RungeKuttaMerson at 1e-10) where Simbody can hold it;
//   - closed loops (docs/loops.md): the start assembled onto the constraints (Newton, then the
//     velocity projected), every run, the linearisation and the step search on the constrained
//     equations (Baumgarte at its default rate, projection after the steps), Simbody's twin
//     with its loops closed; the equations, Φ_q's rank (redundant ones), the largest residuals
//     |Φ| and |Φ_q v| over the reference's samples and rk4's, and the nearest dead point;
// and a verdict: stable; stable only with the implicit integrator; ill-conditioned (cond >
// 1e12); dead point (the motion reaches a configuration where Φ_q loses rank and the
// constrained equations have no solution: named, with the time and the constraint); or
// refused, with the reason.
#pragma once
#include <string>
#include <vector>

#include "core/model/model.hpp"

namespace femdyn::validation {

struct StressScenario {
  VecX q0, qd0;
  double t_end = 1;
  double dt = 1e-3;  // the fixed step at which rk4 and euler are scored
  // Large models (a chain of 1000 links): no step search, no Simbody, and only the fixed-step
  // integrators, against RK4 at half the step (one evaluation costs about a second there).
  bool large = false;
};

inline constexpr int kMinSteps = 200;   // steps of a stability trial run, at least
inline constexpr double kPeriods = 20;  // periods of the stiffest mode it covers, at least

struct StressIntegrator {
  std::string name;
  double largest_stable_step = -1;  // s; −1: not searched (adaptive, or not asked)
  double theory_step = -1;          // s: the linearisation's limit at the initial state
  double theory_step_along = -1;    // s: closed loops, its smallest over the reference's samples
  double error = -1;  // at the scenario's step or tolerance, relative to the state's size
                      // max(1, max |x_ref|); −1: the run failed or was not made
  long steps = 0;
  std::string failure;
  double max_position_residual = -1;  // max |Φ|∞ over the run's samples (−1: no loops, or
                                      // the run was not made)
};

struct StressResult {
  int n = 0;
  std::string refused;  // why the case cannot be run (then nothing else is filled)
  double cond_min = 0, cond_max = 0, asymmetry = 0;
  bool positive_definite = true;
  double stiffest = 0;  // |λ| of the linearisation at the initial state (rad/s)
  std::string reference;
  double energy_error = 0;  // max |E − E0 − W| / max(|E|, kinetic)
  std::vector<StressIntegrator> integrators;
  double simbody_error = -1;  // max ‖(θ, θ̇) − Simbody‖∞ over the samples, relative to the
                              // state's size; −1: not compared
  std::string simbody_note;
  std::string search_note;  // why no step search was made, where none was
  // Closed loops (none: equations 0, the rest −1): the constraint equations, Φ_q's rank at the
  // assembled start and the equations that repeat others, the largest residuals |Φ|∞ (m, rad)
  // and |Φ_q v|∞ over the reference's samples, and the smallest σ_rank/σ_1 of Φ_q there (how
  // near the motion comes to a dead point; sim/stability.hpp dead_point_ratio).
  int equations = 0, rank = -1, redundant = -1;
  double max_position_residual = -1, max_velocity_residual = -1, dead_point_ratio = -1;
  double stiffest_along = -1;  // the largest |λ| over the reference's samples (rad/s)
  std::string verdict;
};

StressResult run_stress(const Model& model, const StressScenario& scenario);

// One line for a refusal found while loading (a ModelError from the case's description).
StressResult refused_case(const std::string& why);
// The verdict of a case whose motion reaches a dead point (`failure` names the time and the
// constraint): "dead point: …".
inline constexpr const char* kDeadPointVerdict = "dead point";

}  // namespace femdyn::validation
