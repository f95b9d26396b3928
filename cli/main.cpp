#include <cstring>
#include <iostream>
#include <new>
#include <string>

#include "cli/commands.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"

namespace {

constexpr const char* kUsage =
    R"(femdyn — equations of motion of mechanisms by the equivalent-element method

usage: femdyn COMMAND MODEL [options]
       femdyn --version

commands:
  info        coordinates, bodies, elements, DOFs kept and left out, the correlation table
  equations   M^s, h, Q and q̈ at a state (D with --tensor)
  compare     relative error of one model's equations against another's
  simulate    the motion from a state under an actuation: trajectory CSV, energy balance
  check       numerical diagnosis: conditioning, stiffest mode, stable steps, suspicious bodies
  kinematics  pose, Jacobian, velocity and J̇v of frames at a state (control)
  linearize   A = ∂(ξ̇, v̇)/∂(ξ, v) and B = ∂(ξ̇, v̇)/∂τ at a state, by analytic derivatives
  statics     where the mechanism rests under springs, gravity and loads (Newton, continuation)
  stress      the stability suite on generated stiff and extreme cases (docs/stability.md)
  study       error against run time of every femdyn and Simbody integrator (work-precision)
  bench       ns per call of M^s, h, g, Q, q̈, τ and D against the model's Simbody twin
  track       computed-torque feed-forward along a smooth motion, replayed in simulation
  validate    the model against its Simbody twin, pointwise and along a trajectory
  import      a URDF robot (or a plugin model) as femdyn JSON
  view        the model and its motion in 3-D: one self-contained HTML page (docs/view.md)

every command takes --help, and --gravity gx,gy,gz to override the model's gravity (m/s^2).
models: JSON files (docs/model-format.md) or URDF files (*.urdf; gravity (0, 0, -9.81) unless
--gravity; the root link welded to the world unless --floating-base; a non-physical body inertia
refused unless --balance-inertia takes the nearest physical one; docs/tutorial.md).
)";

// The last line of defence: whatever reaches here is printed as one safe line, though
// femdyn's own errors are safe already (femdyn::Error). The command is user text too.
void report(const std::string& cmd, const char* what) {
  std::cerr << "femdyn " << femdyn::safe_message(femdyn::truncated(cmd)) << ": "
            << femdyn::safe_message(what) << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace femdyn::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  // The version is CMake's project(VERSION) (CMakeLists.txt); femdyn.__version__ is the same.
  if (!std::strcmp(argv[1], "--version")) {
    if (argc > 2) {
      std::cerr << "femdyn --version: takes no arguments\n";
      return 2;
    }
    std::cout << "femdyn " << FEMDYN_VERSION << "\n";
    return 0;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "info") return cmd_info(argc, argv);
    if (cmd == "equations") return cmd_equations(argc, argv);
    if (cmd == "compare") return cmd_compare(argc, argv);
    if (cmd == "track") return cmd_track(argc, argv);
    if (cmd == "simulate") return cmd_simulate(argc, argv);
    if (cmd == "check") return cmd_check(argc, argv);
    if (cmd == "kinematics") return cmd_kinematics(argc, argv);
    if (cmd == "linearize") return cmd_linearize(argc, argv);
    if (cmd == "statics") return cmd_statics(argc, argv);
    if (cmd == "import") return cmd_import(argc, argv);
#ifdef FEMDYN_WITH_VIEW
    if (cmd == "view") return cmd_view(argc, argv);
#else
    if (cmd == "view")
      throw CliError(
          "this femdyn was built without the 3-D view (three.js missing): run "
          "tools/setup.sh --all");
#endif
#ifdef FEMDYN_WITH_SIMBODY
    if (cmd == "validate") return cmd_validate(argc, argv);
    if (cmd == "study") return cmd_study(argc, argv);
    if (cmd == "stress") return cmd_stress(argc, argv);
    if (cmd == "bench") return cmd_bench(argc, argv);
#else
    if (cmd == "validate" || cmd == "study" || cmd == "stress" || cmd == "bench")
      throw CliError("this femdyn was built without Simbody, which `" + cmd +
                     "` compares with: run tools/setup.sh --all");
#endif
    throw CliError("unknown command " + femdyn::quoted_text(cmd) + " (try femdyn --help)");
  } catch (const CliError& e) {
    report(cmd, e.what());
    return 2;
  } catch (const femdyn::ModelError& e) {
    report(cmd, e.what());
    return 1;
  } catch (const std::bad_alloc&) {
    // The last line of defence: work that allocates by input size is estimated and refused up
    // front (core/workspace/memory.hpp); what no estimate foresaw is still one line of femdyn's.
    std::cerr << "femdyn " << cmd << ": " << femdyn::out_of_memory_text("running " + cmd) << "\n";
    return 1;
  } catch (const std::exception& e) {
    report(cmd, e.what());
    return 1;
  }
}
