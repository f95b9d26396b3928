// The femdyn command line: `femdyn COMMAND MODEL [options]`. Each command returns the exit
// code; user errors are thrown as CliError / ModelError and printed as one line by main().
#pragma once
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/model/errors.hpp"
#include "models/model_files.hpp"

namespace femdyn::cli {

// A bad command line (exit 2). A femdyn::Error: its message is made safe to print as a whole.
struct CliError : Error {
  using Error::Error;
};

// Parsed arguments: positionals and --options (flags map to "").
struct Args {
  std::vector<std::string> positional;
  std::map<std::string, std::string> options;
  bool has(const std::string& k) const { return options.count(k) > 0; }
};

Args parse_args(int argc, char** argv, int first, const std::vector<std::string>& flags,
                const std::vector<std::string>& valued);

// Shared by the commands.
std::vector<double> parse_numbers(const std::string& opt, const std::string& text);
// q from --opt (n_q values, each quaternion of norm 1 within 1e-6, then normalised), or the
// neutral configuration.
VecX configuration_vector(const Args& a, const std::string& opt, const Model& m);
VecX state_vector(const Args& a, const std::string& opt, const Model& m);  // zero if absent
// The state of a command that evaluates one (equations, linearize, kinematics): --q (default the
// neutral configuration), --qd and --tau (default 0). With closed loops and no --q: the neutral
// configuration assembled onto them and q̇ projected, as simulate starts (StateError if they
// cannot close); a --q given is taken as it is, as the Python module takes it.
struct CommandState {
  VecX q, qd, tau;
};
CommandState command_state(const Args& a, const Model& m);
LoadOptions load_options(const Args& a);                                       // --gravity
double number_option(const Args& a, const std::string& opt, double fallback);  // one number
double integer_option(const Args& a, const std::string& opt, double fallback, double min,
                      double max = 1e15);
Model load(const Args& a, std::size_t count = 1);  // the first positional; expects `count`
// For the commands that describe a model without its dynamics (info, import, view): a model
// whose M^s is singular loads, and `singular` says why, naming the coordinates that move no
// inertia, in one line ("" when M^s is regular).
Model load_description(const Args& a, std::string& singular);
// --max-memory GB (a number > 0, below 1e9) as bytes, or 0 when absent: the memory limit's
// default, half the available memory (core/workspace/memory.hpp).
double max_memory(const Args& a);
// The memory `numbers` printed numbers take at most on the way out (as text: 18 bytes each in a
// stream of up to twice its text, copied out; --json: a JSON value each, then its text).
double printed_bytes(double numbers, bool json);
// Refuses, before any work, a command whose estimate `bytes` exceeds the memory limit
// (--max-memory, core/workspace/memory.hpp), naming the model file and `what`.
void require_command_memory(const Args& a, const std::string& what, double bytes);

int cmd_info(int argc, char** argv);
int cmd_equations(int argc, char** argv);
int cmd_compare(int argc, char** argv);
int cmd_track(int argc, char** argv);
int cmd_validate(int argc, char** argv);  // only with FEMDYN_WITH_SIMBODY
int cmd_import(int argc, char** argv);
int cmd_simulate(int argc, char** argv);
int cmd_check(int argc, char** argv);
int cmd_kinematics(int argc, char** argv);
int cmd_linearize(int argc, char** argv);
int cmd_statics(int argc, char** argv);
int cmd_view(int argc, char** argv);    // only with FEMDYN_WITH_VIEW (web/node_modules)
int cmd_study(int argc, char** argv);   // only with FEMDYN_WITH_SIMBODY
int cmd_stress(int argc, char** argv);  // only with FEMDYN_WITH_SIMBODY
int cmd_bench(int argc, char** argv);   // only with FEMDYN_WITH_SIMBODY

}  // namespace femdyn::cli
