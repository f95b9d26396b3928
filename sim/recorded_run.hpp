// A run recorded row by row, as `femdyn simulate` (cli/simulate.cpp) and femdyn.simulate
// (python/bind_simulate.cpp) make it: from the integrator's reset state to t_end, a row at the
// start, then after every `every`-th step and at the last one — or, given `times`, a row at each
// of those times (advance_to, dense output) — and the energy balance over the rows,
//   max |E(t) − E(0) − W(t)|,  W the work of the non-conservative forces (τ, dampers, torques),
// relative to the fixed scale S₀ + max |W| (sim/divergence.hpp): the energy the motion started
// with plus the work done, which does not grow with the error. The run is planned first
// (Integrator::plan: a fixed-step run beyond max_steps is refused before any work), and a
// solution that diverges fails as such (sim/integrator.hpp). Joints that leave their declared
// limits are recorded, once per joint, at the first step that finds them outside; so are joints
// that exceed their velocity limit. τ saturated at effort limits is counted (sim/motion.hpp).
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include "core/dynamics/equations.hpp"
#include "sim/integrator.hpp"

namespace femdyn {

// A joint outside its limits [lower, upper] (the first step found it there).
struct LimitCrossing {
  int joint = -1;  // θ index
  std::string name;
  double t = 0, value = 0, lower = 0, upper = 0;
};

// A joint whose rate |θ̇| exceeded its velocity limit (the first step found it so).
struct VelocityExcess {
  int joint = -1;  // θ index
  std::string name;
  double t = 0, value = 0, limit = 0;
};

// A coordinate whose τ was saturated at its joint's effort limit, in how many evaluations of f.
struct EffortSaturation {
  std::string name;  // the coordinate
  double limit = 0;
  long evaluations = 0;
};

struct RecordedRun {
  Status status;             // the plan's or the integrator's failure (rows end at its last step)
  bool interrupted = false;  // `stop` ended the run
  bool refused = false;      // the plan refused the run before any work (status says why)
  Energy initial;            // E(0)
  double max_balance = 0;    // max over the rows of |E − E(0) − W|
  double scale = 0;          // S₀ + max over the rows of |W| (J): the fixed scale of the balance
  double relative_balance() const { return scale > 0 ? max_balance / scale : max_balance; }
  std::vector<LimitCrossing> limit_crossings;
  std::vector<VelocityExcess> velocity_excesses;
  // Effort limits: evaluations of f whose τ was saturated, steps that ended with τ(t) asked
  // beyond a limit, and the coordinates saturated (those with an evaluation saturated).
  long saturated_evaluations = 0, saturated_steps = 0;
  std::vector<EffortSaturation> saturations;
  // Coupled joints with an effort limit: no τ acts on them directly, so it is not applied.
  std::vector<std::string> unapplied_effort_limits;
  // Closed loops (Model::constraints): the largest |Φ(q)|∞ and |Φ_q v|∞ over the rows.
  double max_position_residual = 0, max_velocity_residual = 0;
  long rows = 0;
  double wall_time = 0;  // s, the whole loop (rows included)
};

class LimitWatch;

// What a run watches, whoever drives the integrator (run_recorded below; the Python Simulator's
// controller loop, python/bind_simulator.cpp): the energy balance and the loops' residuals at each
// row, limit crossings, velocity excesses and saturated steps after each step, and the effort
// saturations since the watch began. One summary for every door (the CLI's and the Python
// module's stats: python/run_stats.hpp).
class RunWatch {
 public:
  explicit RunWatch(Integrator& integ);  // E(0) the integrator's reset; counts from now
  ~RunWatch();
  RunWatch(const RunWatch&) = delete;
  RunWatch& operator=(const RunWatch&) = delete;
  void after_step(Integrator& integ);
  Energy at_row(Integrator& integ);  // E at the row, into the balance
  // The saturations since the start and the effort limits no τ acts on.
  void finish(Integrator& integ);
  RecordedRun& run() { return run_; }

 private:
  RecordedRun run_;
  double initial_scale_ = 0;
  std::unique_ptr<LimitWatch> limits_;
  long saturated_before_ = 0;
  std::vector<long> saturations_before_;
};

// `times` null: rows every `every` steps, the last one at t_end exactly; else a row at each of
// *times (none if it is empty).
// `row(integ, E)` at each row; `stop(t)` after each step (or time): true ends the run.
RecordedRun run_recorded(Integrator& integ, double t_end, long every,
                         const std::vector<double>* times,
                         const std::function<void(const Integrator&, const Energy&)>& row,
                         const std::function<bool(double t)>& stop);

// True when nothing but conservative forces acts: no τ (`driven` false), no damper, friction
// or dissipating stop, no body torque. The energy balance is then the energy drift.
bool conservative(const Model& model, bool driven);

}  // namespace femdyn
