// A run asked for, whoever asks: `femdyn simulate` (cli/simulate.cpp) and femdyn.simulate
// (python/bind_simulate.cpp) translate their arguments into one SimulationRequest; its rules are
// checked in one place (check_request: the integrator's options, the times, the loops'
// stabilisation, τ on undriven coordinates, the memory estimate), the start is assembled onto
// the closed loops, and the run gives one SimulationReport that both doors print or return
// (io/run_report.hpp). The doors keep only what is theirs: parsing, the output file, Ctrl-C.
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/loops/assembly.hpp"
#include "sim/integrator.hpp"
#include "sim/recorded_run.hpp"

namespace femdyn {

// How a door spells its options in a message: option("t_end") is "--t-end" on the command line
// and "t_end" in Python; more_memory(bytes) says how to raise the memory limit there.
struct Door {
  std::function<std::string(std::string_view name)> option;
  std::function<std::string(double bytes)> more_memory;
};

// A request that breaks a rule: one line naming the option (in the door's spelling).
class RequestError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The integrator as a door names it; unset fields keep their defaults.
struct IntegratorChoice {
  std::optional<std::string> integrator;  // rk4, euler, dopri (default), bdf
  std::optional<double> dt;               // rk4, euler
  std::optional<double> rtol, atol;       // dopri, bdf
  std::optional<std::string> jacobian;    // bdf: analytic (default) or differences
  std::optional<double> max_steps;        // an integer in [1, 1e15]
  std::optional<double> max_order;        // bdf: an integer in [1, 5] (default 5)
};
IntegratorOptions integrator_options(const IntegratorChoice& choice, const Door& door);

struct SimulationRequest {
  double t_end = 0;  // s, in (0, 1e9]
  IntegratorOptions options;
  VecX q0, qd0;                     // n_q and n entries (the door checks their sizes)
  std::optional<double> baumgarte;  // 1/s, closed loops only; unset: Motion's default
  // The rows: every `every`-th step, or at the times 0, s, 2s, …, t_end (sample_dt), or at
  // the given times (nondecreasing, in [0, t_end]); at most one of the three is set.
  std::optional<double> every;  // an integer >= 1
  std::optional<double> sample_dt;
  std::optional<std::vector<double>> times;
  // τ(t); none: passive. `tau_largest`: |τ| per coordinate over the run (the undriven
  // coordinates' check); `tau_span`: a table's times, which must cover [0, t_end];
  // `tau_option`: the option that gave τ, for messages ("tau", "tau_csv").
  Actuation tau;
  VecX tau_largest;
  std::optional<std::array<double, 2>> tau_span;
  std::string tau_option = "tau";
  // Memory: the limit given (bytes, 0: the default) and the bytes a door holds per row (0 when
  // its rows go to a file), counted where the number of rows is known up front.
  double max_memory = 0;
  double bytes_per_row = 0;

  long row_every() const { return static_cast<long>(every.value_or(1)); }
  bool driven() const { return static_cast<bool>(tau); }
};

// Closed loops' Baumgarte rate ω (nullopt: the default) against the method that must follow it
// over a run of t_end (0: a stepper whose end is not known yet: the fixed step's bound alone):
// RequestError where it cannot (simulation_request.cpp); every door that runs a model asks it.
void check_baumgarte(const Model& model, const IntegratorOptions& options,
                     std::optional<double> rate, double t_end, const Door& door);

// The request's rules, before any work (RequestError, or MemoryRefused for the memory). With
// closed loops, q0 and qd0 are then assembled onto the constraints (StateError where they
// cannot be) and the assembly is returned; `times` is filled from sample_dt.
StateAssembly check_request(const Model& model, SimulationRequest& request, const Door& door);

// What a run did: the watch's summary (sim/recorded_run.hpp), the integrator's statistics and
// setting, the loops' assembly, and whether nothing but conservative forces acted.
struct SimulationReport {
  RecordedRun run;
  IntegratorStats stats;
  std::string integrator;  // "dopri"
  double t_reached = 0;
  bool conservative = false;
  StateAssembly loops;  // (closed loops only)
  double baumgarte = 0;
  double real_time_factor() const { return stats.wall_time > 0 ? t_reached / stats.wall_time : 0; }
};

// The run of a checked request, rows and stop as in run_recorded.
SimulationReport run_simulation(const Model& model, const SimulationRequest& request,
                                const StateAssembly& loops,
                                const std::function<void(const Integrator&, const Energy&)>& row,
                                const std::function<bool(double t)>& stop);

}  // namespace femdyn
