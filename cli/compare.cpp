// femdyn compare A B: how far model A's equations are from model B's (same coordinates) at
// seeded random states and at given postures — e.g. the paper's discretisation against the
// exact finger.
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>

#include "cli/commands.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "io/output.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kCompareHelp =
    R"(usage: femdyn compare MODEL_A MODEL_B [--states K] [--seed S] [--qd-scale V]
                       [--q a,b,… [--qd …]] [--tau …] [--rtol R] [--json] [--gravity gx,gy,gz]

Relative error of A against B, ‖A − B‖ / ‖B‖ (max-norm), for M^s, h and q̈ (under the actuation
--tau, default 0), at K seeded
random states (q uniform within joint limits, or ±π / ±0.5 m without; q̇ uniform in ±V rad/s,
default V = 2), or at the one state given by --q/--qd. Both models must have the same number of
generalized coordinates. Prints max and median over the states. A model with closed loops is
compared by its spanning tree (M^s, h and the tree's q̈, loops ignored: random states do not close
them), and a note on stderr says so; its constrained q̈ is `femdyn equations`'.
--rtol R (a number > 0) makes it a test: exit 1 if the max relative error of M^s, h or q̈ is
above R (each one above is named on stderr), exit 0 if none is. Without it the exit is 0.
--json prints {"a", "b", "n", "coordinates" (A's), "states", "seed", "max_rel_error",
"median_rel_error"}, with "rtol" and "pass" under --rtol.
)";

double rel(const MatX& a, const MatX& b) { return relative_error(a, b, 0.0); }

constexpr const char* kQuantities[3] = {"M^s", "h", "qdd"};

// The relative errors of M^s, h and q̈ between A and B over the compared states: the max and the
// median of each.
struct CompareErrors {
  std::array<double, 3> max{}, median{};  // M^s, h, q̈
};

CompareErrors compare_states(const Args& a, const Model& A, const Model& B, int K, unsigned seed,
                             double vscale) {
  Workspace wa(A), wb(B);
  std::mt19937 rng(seed);
  std::array<std::vector<double>, 3> e;
  const VecX tau = state_vector(a, "tau", A);
  for (int k = 0; k < K; ++k) {
    VecX q, qd;
    if (a.has("q")) {
      q = configuration_vector(a, "q", A);
      qd = state_vector(a, "qd", A);
    } else {
      q = random_posture(A, rng);
      qd = random_uniform(A.n(), vscale, rng);
    }
    const Status sa = tree_forward_dynamics(A, wa, q, qd, tau),
                 sb = tree_forward_dynamics(B, wb, q, qd, tau);
    evaluate(A, wa, q, qd, tau);
    evaluate(B, wb, q, qd, tau);
    if (!sa.ok || !sb.ok)
      throw CliError("M^s singular at a sampled state: " + (sa.ok ? sb : sa).message);
    e[0].push_back(rel(wa.Ms, wb.Ms));
    e[1].push_back(qd.isZero(0) ? 0.0 : rel(wa.h, wb.h));
    e[2].push_back(rel(wa.qdd, wb.qdd));
  }
  CompareErrors out;
  for (int i = 0; i < 3; ++i) {
    std::sort(e[i].begin(), e[i].end());
    out.max[i] = e[i].back();
    out.median[i] = e[i][e[i].size() / 2];
  }
  return out;
}

void print_compare(const Args& a, const Model& B, int K, unsigned seed, const CompareErrors& e,
                   bool test, int code, double rtol) {
  std::cout << "A: " << escaped(a.positional[0]) << "\nB: " << escaped(B.where) << "\n"
            << K
            << (a.has("q") ? " given state"
                           : " seeded random states (seed " + std::to_string(seed) + ")")
            << "; relative error ‖A − B‖ / ‖B‖\n"
            << "quantity   max         median\n"
            << std::scientific << std::setprecision(3);
  for (int i = 0; i < 3; ++i)
    std::cout << std::left << std::setw(10) << kQuantities[i] << " " << e.max[i] << "   "
              << e.median[i] << "\n";
  if (test) std::cout << (code ? "FAIL" : "PASS") << " (--rtol " << format_number(rtol) << ")\n";
}

}  // namespace

int cmd_compare(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"},
                            {"states", "seed", "qd-scale", "q", "qd", "tau", "rtol", "gravity"});
  if (a.has("help")) {
    std::cout << kCompareHelp;
    return 0;
  }
  if (a.positional.size() != 2) throw CliError("expected two MODEL files (try --help)");
  const Model A = load_model(a.positional[0], load_options(a));
  const Model B = load_model(a.positional[1], load_options(a));
  if (A.n() != B.n())
    throw CliError("the models have " + std::to_string(A.n()) + " and " + std::to_string(B.n()) +
                   " coordinates; compare needs the same");
  for (const Model* m : {&A, &B})
    if (!m->constraints.empty())
      std::cerr << "femdyn compare: note: " << escaped(m->name) << " has closed loops ("
                << m->constraint_rows
                << " constraint equations): the spanning trees are compared, loops ignored\n";
  const int K = a.has("q") ? 1 : static_cast<int>(integer_option(a, "states", 100, 1, INT_MAX));
  const auto seed = static_cast<unsigned>(integer_option(a, "seed", 1, 0, 4294967295.0));
  const double vscale = number_option(a, "qd-scale", 2.0);
  if (vscale < 0) throw CliError("--qd-scale expects one number >= 0");
  // --rtol makes compare a test. A tolerance of 0 or below would fail every real comparison:
  // refused, as parse_numbers refuses NaN, Inf and |R| > 1e100.
  const bool test = a.has("rtol");
  const double rtol = number_option(a, "rtol", 0);
  if (test && !(rtol > 0))
    throw CliError("--rtol: " + format_number(rtol) +
                   " is not a tolerance (expected a number > 0)");
  const CompareErrors e = compare_states(a, A, B, K, seed, vscale);
  // Under --rtol: the quantities whose max error is above it (NaN counts as above).
  std::string above;
  if (test)
    for (int i = 0; i < 3; ++i)
      if (!(e.max[i] <= rtol))
        above += (above.empty() ? "" : ", ") + std::string(kQuantities[i]) + " " +
                 format_number(e.max[i], "%.3e");
  const int code = above.empty() ? 0 : 1;
  if (!above.empty())
    std::cerr << "femdyn compare: max relative error above --rtol " << format_number(rtol) << ": "
              << above << "\n";
  if (a.has("json")) {
    Json j = {{"a", a.positional[0]},
              {"b", a.positional[1]},
              {"n", A.n()},
              {"coordinates", A.coordinate_names},
              {"states", K},
              {"seed", seed},
              {"max_rel_error", {{"M", e.max[0]}, {"h", e.max[1]}, {"qdd", e.max[2]}}},
              {"median_rel_error", {{"M", e.median[0]}, {"h", e.median[1]}, {"qdd", e.median[2]}}}};
    if (test) {
      j["rtol"] = rtol;
      j["pass"] = code == 0;
    }
    std::cout << json_text(j) << "\n";
    return code;
  }
  print_compare(a, B, K, seed, e, test, code, rtol);
  return code;
}

}  // namespace femdyn::cli
