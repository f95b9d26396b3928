// Test helpers: loading models, seeded random mechanisms, finite differences, matrix checks.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "models/model_files.hpp"

namespace femdyn::test {

std::string model_path(const std::string& name);  // FEMDYN_SOURCE_DIR/models/name
std::vector<std::string> bundled_models();        // file names of models/*.json, sorted
std::string read_file(const std::string& path);   // the whole file as text
Model load_text(const std::string& json_text, const CompileOptions& options = {});
// The ModelError's message of load_text(json_text), or "(loaded)".
std::string text_error(const std::string& json_text);

// A planar serial chain of `n` links of 0.1 m, a 1 kg point mass at each link's end, under
// gravity, as JSON text.
std::string planar_chain(int n);

// One revolute joint 'theta' about y carrying a 1 kg point 1 m out along x (1 kg·m² about the
// joint; body 'arm'), with a joint spring k and damper c (ω = √k, ζ = c / 2ω), under gravity g
// along −z (θ > 0 turns the arm down).
std::string arm_json(double k, double c = 0, double g = 0);

// A seeded random tree as JSON text: random axes, offsets and rpy, full physical inertia
// tensors (rigid_body), revolute and prismatic joints; `branching` in [0, 1]: the chance a
// body hangs from an earlier body instead of the last one.
std::string random_tree_json(unsigned seed, int bodies, double branching, bool prismatic,
                             double gravity = 9.81);

// The model's own routes and the two whole alternatives (the transform T with node sweeps, and
// composite inertias with Newton–Euler, both solved by Cholesky): what a relation is checked on.
inline std::vector<RouteChoice> main_routes() {
  return {{},
          {.mass = MassRoute::Transform,
           .force = ForceRoute::Nodes,
           .dynamics = DynamicsRoute::Cholesky},
          {.mass = MassRoute::Composite,
           .force = ForceRoute::Bodies,
           .dynamics = DynamicsRoute::Cholesky}};
}

// A random tree with every element type, fixed joints, springs, dampers, point loads and
// torques, and (with `couplings`) joints that follow others linearly; with `several_rates`,
// universal, planar, spherical and free joints in place of half the plain revolute ones, and a
// free-floating base for odd seeds.
std::string mixed_tree_json(unsigned seed, int bodies, double branching, bool couplings,
                            bool several_rates = false);

// A seeded random 6-body tree whose joints j2, j4, j5 follow the coordinates j0, j1, j3 through
// nonlinear laws: a four-bar (j2 of j1), a polynomial in two joints (j4 of j0 and j3) and a
// spline of a coupled joint (j5 of j2).
std::string nonlinear_coupled_tree_json(unsigned seed);

// `text` with a rod of 0.3 kg from every body on a fixed joint under another body to a node of
// that parent (seeded random nodes): elements spanning two bodies that keep their length. Counts
// them into `rods`.
std::string with_rods(const std::string& text, unsigned seed, int& rods);

// max |a − b| / max(|b|, floor)
double rel_error(const MatX& a, const MatX& b, double floor = 1e-12);

// World position of translation DOF i's node component, for finite differences of u(q).
double translation_value(const Model& m, const Workspace& ws, int i);

// The femdyn command (FEMDYN_BINARY) run by the shell with `args`: exit code and the output
// (stdout and stderr together unless args redirect them).
struct Run {
  int code;
  std::string out;
};
Run run(const std::string& args);
Run run_shell(const std::string& command);  // any shell command

// A scratch directory for one test case (in the system's temporary directory, named after the
// case), emptied at the start and removed afterwards.
// A test's own folder under the temporary directory, per process (two suites at once, such as
// the sanitizer build's and the release build's, never share one), removed when done.
struct Scratch {
  std::filesystem::path dir;
  explicit Scratch(const std::string& name)
      : dir(std::filesystem::temp_directory_path() /
            ("femdyn_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  ~Scratch() { std::filesystem::remove_all(dir); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  std::string operator/(const std::string& f) const { return (dir / f).string(); }
  std::size_t files() const {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir), {}));
  }
};

}  // namespace femdyn::test
