// femdyn stress: the stability suite on generated cases (cli/stress_cases.hpp,
// validation/stress.hpp); writes stress.md and stress.csv (docs/stability.md is spliced from
// stress.md by tools/update-stability-docs.sh).
#include "validation/stress.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/stress_cases.hpp"
#include "compile/compile.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "io/atomic_file.hpp"
#include "io/csv.hpp"
#include "io/output.hpp"
#include "models/model_files.hpp"

namespace femdyn::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kStressHelp =
    R"(usage: femdyn stress [--out DIR] [--quick] [--class NAME] [--json] [--force]

Runs the stability suite on generated cases (docs/stability.md): stiff joint springs
(ω = 1e1…1e5 rad/s, damping ratio 0…100), mass ratios up to 1e6 and lengths 1e-4…10 m in one
chain, joints and a gyroscopic rotor at 1e3 rad/s, slender bars with negative lumped rotary
inertia, near-singular postures, a chain of 1000 links, zero gravity and 1000 g, a zero-mass
chain end, and closed loops (a four-bar at its dead point and one passing near its change
point, a parallelogram closed by a redundant 3-D ball, a four-bar with a stiff spring). For
each: cond(M^s) along the motion, symmetry and definiteness, the largest stable step of rk4 and
euler (bisection of real runs), every integrator's error at a fixed step or tolerance, the
energy balance, agreement with Simbody, and a verdict: stable, stable only with bdf (stiff and
dissipative), stiff and undamped (bdf stays stable only by damping the fast mode numerically:
remove, damp or resolve it, as femdyn check says), ill-conditioned, dead point (the motion
reaches a configuration where the constraint Jacobian loses rank and the constrained equations
have no solution: the time and the constraint are named), or refused with the reason.
A case with closed loops starts assembled onto them, moves by the constrained equations
(Baumgarte's default rate, projection after the steps; the modes and theory steps are those of
the constrained linearisation, as in femdyn check but without Baumgarte's pair, which the
projection removes; also their smallest along the reference, "along") and reports its
equations, Phi_q's rank (redundant ones), the largest residuals |Phi| of the reference and of
rk4, and the nearest dead point (smallest sigma_min/sigma_max of Phi_q along the reference).
Writes DIR/stress.md and DIR/stress.csv (default DIR ./stress; existing files need --force).
--quick: a subset of each class, smaller sizes. --class NAME: one class (springs, ratios,
speeds, slender bars, postures, size, gravity, singular, loops). --json: the results on stdout.
)";

// A table cell: three digits, or a dash for "not measured" (−1).
std::string g(double x) { return x < 0 ? "—" : format_short(x); }

// The loops cell: "3 eq., rank 2 (1 redundant); max |Φ| 1e-15 (rk4 2e-16); σ ratio ≥ 0.1" (σ_min
// / σ_max of Φ_q along the reference), or a dash without constraints.
std::string loops_cell(const validation::StressResult& r) {
  if (r.equations == 0) return "—";
  std::string s = std::to_string(r.equations) + " eq., rank " + std::to_string(r.rank);
  if (!r.refused.empty()) return s + " at the start";  // (at a dead point: not redundancy)
  s += " (" + std::to_string(r.redundant) + " redundant)";
  if (r.max_position_residual < 0) return s;
  const double rk4 = r.integrators.empty() ? -1 : r.integrators[0].max_position_residual;
  return s + "; max \\|Φ\\| " + g(r.max_position_residual) + " (rk4 " + g(rk4) + "); σ ratio ≥ " +
         g(r.dead_point_ratio);
}

Json loops_json(const validation::StressResult& r) {
  const auto number = [](double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); };
  return {{"equations", r.equations},
          {"rank", r.rank},
          {"redundant", r.redundant},
          {"max_position_residual", r.max_position_residual},
          {"max_velocity_residual", r.max_velocity_residual},
          {"dead_point_ratio", number(r.dead_point_ratio)},
          {"stiffest_along", r.stiffest_along}};
}

// A case's integrator figures by index (rk4, euler, dopri, bdf), -1 where there is none.
double column(const validation::StressResult& r, std::size_t i,
              double validation::StressIntegrator::*field) {
  return i < r.integrators.size() ? r.integrators[i].*field : -1.0;
}
double err(const validation::StressResult& r, std::size_t i) {
  return column(r, i, &validation::StressIntegrator::error);
}
double step(const validation::StressResult& r, std::size_t i) {
  return column(r, i, &validation::StressIntegrator::largest_stable_step);
}
double theory(const validation::StressResult& r, std::size_t i) {
  return column(r, i, &validation::StressIntegrator::theory_step);
}
// "0.417" at the start; closed loops add "; ≥ 0.0123 along" (the smallest along the motion).
std::string theory_cell(const validation::StressResult& r, std::size_t i) {
  const double along = column(r, i, &validation::StressIntegrator::theory_step_along);
  return g(theory(r, i)) + (along >= 0 ? "; " + g(along) + " along" : std::string());
}

// One case compiled and run (a refusal is its result).
validation::StressResult run_case(const StressCase& c) {
  validation::StressResult r;
  try {
    const Model m = compile(parse_model_json(c.model, "stress case '" + c.name + "'"));
    validation::StressScenario s;
    const auto state = [&](const std::vector<double>& v) -> VecX {
      if (v.empty()) return VecX::Zero(m.n());
      if (static_cast<int>(v.size()) != m.n())
        throw std::logic_error("stress case '" + c.name + "': state of the wrong size");
      return Eigen::Map<const VecX>(v.data(), m.n());
    };
    s.q0 = state(c.q0);
    s.qd0 = state(c.qd0);
    s.t_end = c.t_end;
    s.dt = c.dt;
    s.large = c.large;
    r = validation::run_stress(m, s);
  } catch (const Error& e) {
    r = validation::refused_case(e.what());
  }
  return r;
}

Json case_json(const StressCase& c, const validation::StressResult& r, double seconds) {
  Json j = {{"class", c.klass},     {"case", c.name},       {"description", c.description},
            {"expected", c.expect}, {"verdict", r.verdict}, {"n", r.n},
            {"seconds", seconds}};
  if (r.equations > 0) j["loops"] = loops_json(r);
  if (r.refused.empty()) {
    j.update({{"cond_min", r.cond_min},
              {"cond_max", r.cond_max},
              {"positive_definite", r.positive_definite},
              {"asymmetry", r.asymmetry},
              {"stiffest", r.stiffest},
              {"reference", r.reference},
              {"energy_error", r.energy_error},
              {"simbody_error", r.simbody_error},
              {"simbody_note", r.simbody_note},
              {"search_note", r.search_note},
              {"dt", c.dt}});
    Json its = Json::array();
    for (const auto& it : r.integrators)
      its.push_back({{"integrator", it.name},
                     {"largest_stable_step", it.largest_stable_step},
                     {"theory_step", it.theory_step},
                     {"theory_step_along", it.theory_step_along},
                     {"error", it.error},
                     {"steps", it.steps},
                     {"failure", it.failure},
                     {"max_position_residual", it.max_position_residual}});
    j["integrators"] = its;
  }
  return j;
}

void md_row(std::ostream& md, const StressCase& c, const validation::StressResult& r) {
  md << "| " << c.klass << " | " << c.name << " | " << r.n << " | ";
  if (r.refused.empty())
    md << g(r.cond_min) << " … " << g(r.cond_max) << " | " << (r.positive_definite ? "yes" : "no")
       << " | " << (r.stiffest > 0 ? g(r.stiffest) : "—") << " | "
       << (r.search_note.empty() ? g(step(r, 0)) + " (" + theory_cell(r, 0) + ") / " +
                                       g(step(r, 1)) + " (" + theory_cell(r, 1) + ")"
                                 : r.search_note)
       << " | at " << g(c.dt) << " s: " << (err(r, 0) < 0 ? "unstable" : g(err(r, 0))) << " / "
       << (err(r, 1) < 0 ? "unstable" : g(err(r, 1))) << "; rtol 1e-6: " << g(err(r, 2)) << " / "
       << g(err(r, 3)) << " | " << g(r.energy_error) << " | "
       << (r.simbody_error >= 0     ? g(r.simbody_error)
           : r.simbody_note.empty() ? "—"
                                    : "not run")
       << " | " << loops_cell(r) << " | " << r.verdict << " |\n";
  else
    md << "— | — | — | — | — | — | — | " << loops_cell(r) << " | " << r.verdict << " |\n";
}

void csv_row(std::ostream& csv, const StressCase& c, const validation::StressResult& r) {
  std::string verdict = r.verdict;
  std::replace(verdict.begin(), verdict.end(), ',', ';');
  csv << csv_field(c.klass) << "," << csv_field(c.name) << "," << r.n << "," << r.cond_min << ","
      << r.cond_max << "," << r.positive_definite << "," << r.stiffest << "," << step(r, 0) << ","
      << step(r, 1) << "," << theory(r, 0) << "," << theory(r, 1) << "," << c.dt << "," << err(r, 0)
      << "," << err(r, 1) << "," << err(r, 2) << "," << err(r, 3) << "," << r.energy_error << ","
      << r.simbody_error << "," << r.equations << "," << r.rank << "," << r.redundant << ","
      << r.max_position_residual << "," << r.dead_point_ratio << ",\"" << verdict << "\"\n";
}

}  // namespace

int cmd_stress(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "quick", "json", "force"}, {"out", "class"});
  if (a.has("help")) {
    std::cout << kStressHelp;
    return 0;
  }
  if (!a.positional.empty()) throw CliError("stress takes no MODEL (try --help)");
  std::vector<StressCase> cases = stress_cases(a.has("quick"));
  if (a.has("class")) {
    std::erase_if(cases, [&](const StressCase& c) { return c.klass != a.options.at("class"); });
    if (cases.empty())
      throw CliError("--class: no class " + quoted_text(a.options.at("class")) + " (try --help)");
  }
  const fs::path dir = a.has("out") ? fs::path(a.options.at("out")) : fs::path("stress");
  const bool write = !a.has("json") || a.has("out");
  if (write) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir))
      throw CliError("--out " + dir.string() + ": cannot create the directory");
    for (const char* f : {"stress.md", "stress.csv"})
      if (fs::exists(dir / f) && !a.has("force"))
        throw CliError((dir / f).string() + ": exists (use --force to replace it)");
  }
  const bool tty = isatty(STDERR_FILENO) == 1;

  Json results = Json::array();
  std::ostringstream md, csv;
  md << "| class | case | n | cond(M^s) along the motion | SPD | stiffest mode (rad/s) | "
        "largest stable step rk4 / euler (s), measured (linear theory) | relative error: rk4 / "
        "euler at the fixed step, "
        "dopri / bdf at rtol 1e-6 | energy balance | Simbody (relative) | loops: equations, rank; "
        "largest residual, nearest dead point | verdict "
        "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  csv << "class,case,n,cond_min,cond_max,positive_definite,stiffest,rk4_stable_step,"
         "euler_stable_step,rk4_theory_step,euler_theory_step,dt,rk4_error,euler_error,dopri_error,"
         "bdf_error,energy_error,"
         "simbody_error,equations,rank,redundant,max_position_residual,dead_point_ratio,verdict\n";
  for (const StressCase& c : cases) {
    const auto begin = std::chrono::steady_clock::now();
    const validation::StressResult r = run_case(c);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    if (tty) std::cerr << "  " << c.name << ": " << r.verdict << " (" << g(seconds) << " s)\n";
    results.push_back(case_json(c, r, seconds));
    md_row(md, c, r);
    csv_row(csv, c, r);
  }
  if (write) {
    for (const auto& [name, text] : {std::pair{"stress.md", md.str()}, {"stress.csv", csv.str()}}) {
      AtomicFile f((dir / name).string(), true);
      f.stream() << text;
      f.commit();
    }
  }
  if (a.has("json"))
    std::cout << json_text(results) << "\n";
  else
    std::cout << md.str() << "wrote " << escaped((dir / "stress.md").string()) << ", stress.csv\n";
  return 0;
}

}  // namespace femdyn::cli
