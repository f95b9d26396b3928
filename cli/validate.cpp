// femdyn validate MODEL…: the model against its Simbody twin (validation/validate.hpp).
#include "validation/validate.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <deque>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "io/output.hpp"
#include "io/urdf_loader.hpp"
#include "validation/file_rows.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kValidateHelp =
    R"(usage: femdyn validate MODEL… [--states K] [--seed S] [--t-end T] [--tol X]
                        [--qd-scale V] [--budget SECONDS] [--max-memory GB]
                        [--json | --markdown] [--gravity gx,gy,gz]

Builds each model's Simbody twin (same tree, each body's mass properties from its equivalent
elements, same forces) and compares, at K seeded random states (default 20; q within joint
limits or ±π rad / ±0.5 m, q̇ in ±V, default 2, τ in ±1, q̈ in ±5): M^s, h, Q, q̈ and inverse
dynamics τ, each as max abs and max relative error ‖femdyn − Simbody‖∞ / ‖Simbody‖∞, against
the tolerance X (default max(1e-10, ε·d²) for a tree d bodies deep: round-off grows with d;
docs/validation.md). For a URDF file, also the import itself ("import"): M^s, h, Q
against a second Simbody model built straight from the XML, not from femdyn's reading of it.
A model with a nonlinear coupling law or a rod spanning two bodies gets a closed-loop twin:
every joint a mobilizer, each law a coordinate coupler, each rod a body on a LineOrientation
joined by a Ball constraint; its M^s, h, Q, q̈ and τ come from Simbody's constrained forward
dynamics alone, and "loop" is its constraint error at femdyn's θ = g(q), θ̇ = G q̇ (relative
to the longest rod). Up to 1000 coordinates, the kinematics for control too, at the same
states: every frame's pose, velocity J q̇ and acceleration J q̈ + J̇q̇ (q̈ each engine's own
forward dynamics under τ), its Jacobian J column by column (up to 300 coordinates), and the
mechanism's mass, centre of mass and inertia about it, its velocity J_c q̇ and acceleration,
and the central momentum A_G q̇ (Simbody's calcSystemCentralMomentum). Then integrates the passive motion (τ = 0) from the first
state for T seconds (default 0.25; 0 skips): femdyn by RK4 (step 1 ms, halved until its own
error estimate is below 1e-9), Simbody by RungeKuttaMerson at accuracy 1e-10 and 1e-12, and
compares the joint states (θ, θ̇) over time against 10x the sum of both error estimates.
A model with loop constraints (docs/loops.md) gets them as Simbody constraints (ball: Ball;
ball in a plane, point_on_line: PointOnLine; point_on_plane: PointInPlane; weld: Weld; distance:
Rod; gear: CoordinateCoupler) and its two-point springs as TwoPointLinearSpring and
TwoPointLinearDamper. M^s, h, Q, q̈, τ and the kinematics compare the spanning tree (springs
on, constraints off); at K states assembled by femdyn (Φ = 0, Φ_q q̇ = 0) "constrained qdd"
compares q̈ of the constrained dynamics (Baumgarte off), "constraint forces" Φ_qᵀλ against
Simbody's −Gᵀλ, and "closure" Simbody's own constraint errors at femdyn's assembled states
(relative to the largest attachment offset); the trajectory ("constrained trajectory") is the
closed mechanism's, from the first state assembled.
Beyond 1000 coordinates M^s is compared by its products with 4 seeded random vectors (M^s V,
Simbody's O(n) multiplyByM) rather than entry by entry.
Bounded work: before any state is compared, each model's time and memory are estimated (a model
of the costs, from n and a timed probe of each engine); beyond --budget seconds (default 120)
or --max-memory GB (default: half the available memory, MemAvailable in /proc/meminfo) the
command refuses with one line on stderr (the estimate and how to proceed) and exits 1. During
the trajectory, femdyn's step halving and Simbody's runs stop where the budget ends. On a
terminal a progress line shows the work done against the estimate.
Exit 1 if any check fails; 3 if none fails but a model could not be compared, one line saying
why (a body Simbody cannot hold: a rotary inertia without mass), with NOT COMPARED. --json: one object per model (an array for several models);
--markdown: one table row per model (docs/validation.md). The JSON has the whole series: the
trajectory's sample times "t", "state_error" and the energy of both runs.
)";

constexpr int kNameWidth = 18;  // "frame acceleration"

// The kinematics for control (frames, centre of mass, momentum): one markdown column, their
// largest relative error.
bool kinematic(const std::string& name) {
  return name.rfind("frame ", 0) == 0 || name.rfind("com", 0) == 0 || name == "momentum";
}

// The closed loop's rows: the rods' and couplers' closure, or the loop constraints' constrained
// q̈, constraint forces and closure; one markdown column, their largest relative error.
bool loop_row(const std::string& name) {
  return name == "loop" || name == "constrained qdd" || name == "constraint forces" ||
         name == "closure";
}

Json report_json(const std::string& path, const Model& m, const validation::ValidationReport& r) {
  Json rel = Json::object(), abs = Json::object();
  for (const auto& q : r.quantities) {
    rel[q.name] = q.max_rel;
    abs[q.name] = q.max_abs;
  }
  const auto& t = r.trajectory;
  Json traj = {
      {"run", t.run},
      {"constrained", t.constrained},
      {"t_end", t.t_end},
      {"max_state_error", t.max_state_error},
      {"rk4_step", t.rk4_step},
      {"rk4_error_estimate", t.rk4_error_estimate},
      {"simbody_error_estimate", t.simbody_error_estimate},
      {"resolved", t.resolved},
      {"tolerance", t.tolerance},
      {"energy_change", {{"femdyn", t.energy_change_femdyn}, {"simbody", t.energy_change_simbody}}},
      {"pass", t.pass()},
      {"t", t.t},
      {"state_error", t.error},
      {"energy", {{"femdyn", t.energy_femdyn}, {"simbody", t.energy_simbody}}}};
  if (!t.run) traj["skipped"] = t.skipped;
  if (!t.stopped.empty()) traj["stopped"] = t.stopped;
  if (!t.refinement.empty()) traj["refinement"] = t.refinement;
  const auto& e = r.estimate;
  const Json work = {
      {"estimated_s", e.seconds()},
      {"estimated_pointwise_s", e.pointwise},
      {"estimated_trajectory_s", e.trajectory},
      {"setup_s", e.setup},
      {"wall_time_s", r.wall_time},
      {"estimated_memory_bytes", e.bytes},
      {"budget_s", e.budget},
      {"memory_limit_bytes", std::isfinite(e.memory_limit) ? Json(e.memory_limit) : Json(nullptr)},
      {"mass_comparison", r.dense_mass ? "entries" : "products"}};
  return {{"model", path},
          {"states", r.states},
          {"n", r.n},
          {"coordinates", m.coordinate_names},
          {"tolerance", r.quantities.empty() ? 0.0 : r.quantities[0].tolerance},
          {"max_rel_error", rel},
          {"max_abs_error", abs},
          {"trajectory", traj},
          {"notes", r.notes},
          {"work", work},
          {"failure", r.failure},
          {"compared", !r.not_comparable},
          {"pass", r.pass()}};
}

void print_text(const std::string& path, const validation::ValidationReport& r) {
  if (!r.failure.empty()) {
    std::cout << escaped(path) << ": no comparison possible: " << safe_message(r.failure) << "\n";
    for (const auto& n : r.notes) std::cout << "note: " << n << "\n";
    std::cout << (r.not_comparable ? "NOT COMPARED\n" : "FAIL\n");
    return;
  }
  const bool mujoco_only = r.quantities.size() == 1 && r.quantities[0].name == "mujoco";
  std::cout << escaped(path) << " (" << r.n << " coordinates) against "
            << (mujoco_only ? "MuJoCo's compile of the file" : "Simbody") << ", " << r.states
            << " seeded random states\n"
            << std::left << std::setw(kNameWidth) << "quantity"
            << " max abs err   max rel err   tolerance   result\n";
  for (const auto& q : r.quantities)
    std::cout << std::left << std::setw(kNameWidth) << (q.name == "M" ? "M^s" : q.name) << " "
              << std::setw(13) << format_sci(q.max_abs) << " " << std::setw(13)
              << format_sci(q.max_rel) << " " << std::setw(11) << format_sci(q.tolerance) << " "
              << (q.pass() ? "PASS" : "FAIL") << "\n";
  const auto& t = r.trajectory;
  if (t.run)
    std::cout << std::setw(kNameWidth) << (t.constrained ? "constrained trajectory" : "trajectory")
              << " " << std::setw(13) << format_sci(t.max_state_error) << " " << std::setw(13) << ""
              << " " << std::setw(11) << format_sci(t.tolerance) << " "
              << (t.pass() ? "PASS" : "FAIL") << "   (" << t.t_end
              << " s; error estimates: femdyn RK4 (step " << format_sci(t.rk4_step) << " s) "
              << format_sci(t.rk4_error_estimate) << ", Simbody "
              << format_sci(t.simbody_error_estimate) << "; energy change femdyn "
              << format_sci(t.energy_change_femdyn) << " J, Simbody "
              << format_sci(t.energy_change_simbody) << " J)\n";
  else if (!t.stopped.empty())
    std::cout << "trajectory   FAIL: not compared within the budget: " << t.stopped
              << " (shorten --t-end, or raise --budget)\n";
  else
    std::cout << "trajectory not compared: " << t.skipped << "\n";
  if (t.run && !t.refinement.empty()) std::cout << "femdyn's RK4 step " << t.refinement << "\n";
  if (t.run && !t.error.empty()) {  // the state error over time, at five of the samples
    std::cout << "  state error over time:";
    for (std::size_t k = 0; k < 5; ++k) {
      const std::size_t i = k * (t.t.size() - 1) / 4;
      std::cout << "  t=" << t.t[i] << " s " << format_sci(t.error[i]);
    }
    std::cout << "\n";
  }
  if (t.run && !t.resolved)
    std::cout << "trajectory unresolved: the integrators' own error estimates exceed 1e-6 of the "
                 "state; the motion is too fast or chaotic over this time (try a shorter --t-end"
              << (t.refinement.find("budget") != std::string::npos ? ", or raise --budget" : "")
              << ")\n";
  for (const auto& n : r.notes) std::cout << "note: " << n << "\n";
  std::cout << (r.pass() ? "PASS" : "FAIL") << "\n";
}

void print_markdown_row(const std::string& path, const validation::ValidationReport& r) {
  if (!r.failure.empty()) {
    std::cout << "| `" << path << "` | " << r.n << " | — | — | — | — | — | — | — | — | "
              << (r.not_comparable ? "NOT COMPARED: " : "FAIL: ") << r.failure << " |\n";
    return;
  }
  std::cout << "| `" << path << "` | " << r.n;
  double loop = -1;        // the closed loop's rows, a column of their own
  double kinematics = -1;  // the largest of theirs, if compared
  for (const auto& q : r.quantities)
    if (kinematic(q.name))
      kinematics = std::max(kinematics, q.max_rel);
    else if (loop_row(q.name))
      loop = std::max(loop, q.max_rel);
    else if (q.name != "import")
      std::cout << " | " << format_sci(q.max_rel);
  std::cout << " | " << (loop >= 0 ? format_sci(loop) : "—");
  std::cout << " | " << (kinematics >= 0 ? format_sci(kinematics) : "—");
  const auto& t = r.trajectory;
  std::cout << " | "
            << (t.run ? (t.constrained ? "closed: " : "") + format_sci(t.max_state_error) +
                            " (tol " + format_sci(t.tolerance) + ")"
                : t.stopped.empty() ? "—"
                                    : "not within the budget")
            << " | " << (r.pass() ? "PASS" : "FAIL") << " |\n";
}

int positive_int(const Args& a, const std::string& opt, int fallback, int min) {
  return static_cast<int>(integer_option(a, opt, fallback, min, INT_MAX));
}

double nonnegative(const Args& a, const std::string& opt, double fallback) {
  const double v = number_option(a, opt, fallback);
  if (v < 0) throw CliError("--" + opt + " expects one number >= 0");
  return v;
}

}  // namespace

int cmd_validate(int argc, char** argv) {
  const Args a =
      parse_args(argc, argv, 2, {"help", "json", "markdown"},
                 {"states", "seed", "t-end", "tol", "qd-scale", "gravity", "budget", "max-memory"});
  if (a.has("help")) {
    std::cout << kValidateHelp;
    return 0;
  }
  if (a.positional.empty()) throw CliError("expected a MODEL file (try --help)");
  if (a.has("json") && a.has("markdown"))
    throw CliError("--json and --markdown exclude each other");
  validation::ValidationOptions o;
  o.states = positive_int(a, "states", o.states, 1);
  o.seed = static_cast<unsigned>(positive_int(a, "seed", static_cast<int>(o.seed), 0));
  o.t_end = nonnegative(a, "t-end", o.t_end);
  if (a.has("tol")) {
    o.tolerance = nonnegative(a, "tol", o.tolerance);
    if (!(o.tolerance > 0 && o.tolerance < 1)) throw CliError("--tol expects a number in (0, 1)");
  }
  o.qd_scale = nonnegative(a, "qd-scale", o.qd_scale);
  if (o.t_end > validation::kMaxTrajectoryTime)
    throw CliError("--t-end expects at most " + format_number(validation::kMaxTrajectoryTime) +
                   " s");
  o.budget = number_option(a, "budget", o.budget);
  if (!(o.budget > 0 && o.budget < 1e9))
    throw CliError("--budget expects a positive number of seconds (below 1e9)");
  o.memory_limit = max_memory(a);

  // Load every model first: a bad file fails before any work.
  std::deque<Model> models;  // (Model is move-only and its move may throw: no vector)
  for (const std::string& path : a.positional) models.push_back(load_model(path, load_options(a)));

  // Then every model's twin and estimate: work beyond the budget is refused before any state.
  std::vector<std::unique_ptr<validation::Validator>> validators;
  bool refused = false;
  for (std::size_t i = 0; i < models.size(); ++i) {
    validators.push_back(std::make_unique<validation::Validator>(models[i], o));
    if (const std::string why = validators.back()->refusal(a.positional[i]); !why.empty()) {
      std::cerr << "femdyn validate: " << why << "\n";
      refused = true;
    }
  }
  if (refused) return 1;

  bool any_failed = false, any_not_compared = false;
  Json reports = Json::array();
  if (a.has("markdown"))
    std::cout << "| model | n | M^s | h | Q | q̈ | τ | loop | frames, COM, momentum | trajectory "
                 "state error | result |\n"
              << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < models.size(); ++i) {
    validation::ValidationReport r;
    {
      // The estimated seconds of work done against those planned (revised as it goes).
      Progress progress(validators[i]->estimate().seconds(), "s", "work");
      validators[i]->set_progress([&](double done, double total) { progress.update(done, total); });
      r = validators[i]->run();
      validators[i].reset();  // its workspace and twin
    }
    validation::add_file_rows(r, models[i], a.positional[i], o, load_options(a));
    any_failed = any_failed || (!r.pass() && !r.not_comparable);
    any_not_compared = any_not_compared || r.not_comparable;
    if (a.has("json"))
      reports.push_back(report_json(a.positional[i], models[i], r));
    else if (a.has("markdown"))
      print_markdown_row(a.positional[i], r);
    else
      print_text(a.positional[i], r);
  }
  if (a.has("json")) std::cout << json_text((reports.size() == 1 ? reports[0] : reports)) << "\n";
  return any_failed ? 1 : any_not_compared ? 3 : 0;
}

}  // namespace femdyn::cli
