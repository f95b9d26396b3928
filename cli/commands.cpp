#include "cli/commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "compile/correlation.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/output.hpp"
#include "models/model_files.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kInfoHelp = R"(usage: femdyn info MODEL [--json] [--gravity gx,gy,gz]

Prints the generalized coordinates, joints (with the coupling level θ = C q + θ0), bodies and
their elements, the flexible bars (each with its parts and stations, --json "bars"), the transition coordinates u kept and those left out, the routes (which
algorithm computes M^s, h and τ, q̈, and the closed loops' q̈: docs/design.md), and the
correlation table N_m (one row per element; per node x y z rx ry rz; 0 = left out).
A model whose M^s is singular (a massless chain end) is described all the same, with a note
naming the coordinates that move no inertia (--json: "mass_matrix_singular"); import and view
load it too, and the commands that compute motion refuse it.
)";

constexpr const char* kEquationsHelp =
    R"(usage: femdyn equations MODEL [--q a,b,…] [--qd …] [--tau …] [--tensor] [--json]
                        [--max-memory GB] [--gravity gx,gy,gz]

Prints the system equations M^s(q) q̈ + h(q, q̇) = Q(q, q̇, τ) at the state, and
q̈ = (M^s)⁻¹(Q − h). Omitted q, q̇, τ are zero; τ is the actuation force on each generalized
coordinate. --tensor adds D (n x n x n) with h_a = Σ_bc D_abc q̇_b q̇_c.
With closed loops (docs/loops.md) M^s, h, Q are the spanning tree's and q̈ is the closed
mechanism's, M^s q̈ + h = Q + Φ_qᵀ λ with Φ_q q̈ = −Φ̇_q q̇, printed with λ and Φ_qᵀ λ; the state
must close the loops (else exit 1 naming the constraint), and without --q the neutral
configuration is assembled onto them first (q̇ projected), as simulate starts.
--json prints one object: {"n", "coordinates", "q", "qd", "tau", "M", "h", "Q", "qdd",
"routes"[, "D"]} (n the number of coordinates, "coordinates" their names, "routes" which
algorithm computed each, as info prints them; with loops also "lambda" and "constraint_forces";
"failure" when qdd is null).
M^s and its printed form grow as n²: beyond the memory limit (--max-memory GB, default half the
available memory) the command is refused before any work, with the memory it would need.
)";

// The memory `equations` needs, at most: a workspace that has formed and factorised M^s, and the
// printed n² + 5n numbers. Text: 18 bytes a number ("% .10e" and a space) in an ostringstream
// whose capacity is at most twice its text, then copied out (3x); --json: a JSON value a number
// (16 bytes, in arrays of at most twice the capacity), then its text the same way (about 24
// bytes a number, 3x). An upper bound by construction, not a measurement.
double equations_bytes(const Model& m, bool json) {
  const double n = m.n();
  return evaluation_bytes(m) + printed_bytes(n * n + 5 * n, json);
}

}  // namespace

double printed_bytes(double numbers, bool json) {
  return json ? (2 * 16 + 3 * 24) * numbers : 3 * 18 * numbers;
}

void require_command_memory(const Args& a, const std::string& what, double bytes) {
  require_memory(a.positional[0] + ": " + what, bytes, max_memory(a),
                 "use " + max_memory_option(bytes) + " if that much memory is free");
}

std::vector<double> parse_numbers(const std::string& opt, const std::string& text) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    std::size_t used = 0;
    double x = 0;
    bool out_of_range = false;
    try {
      x = std::stod(item, &used);
    } catch (const std::out_of_range&) {
      // Overflow is out of range; underflow (1e-400) is a number too small to matter: its
      // nearest double (0 or a subnormal) is taken.
      char* end = nullptr;
      x = std::strtod(item.c_str(), &end);
      used = static_cast<std::size_t>(end - item.c_str());
      out_of_range = !(std::abs(x) < 1);
    } catch (const std::exception&) {
      used = 0;
    }
    if (out_of_range || (std::isfinite(x) && std::abs(x) > kMaxMagnitude))
      throw CliError("--" + opt + ": " + quoted_text(item) + kOutOfRange);
    if (item.empty() || used != item.size())
      throw CliError("--" + opt + ": " + quoted_text(item) + " is not a number");
    if (!std::isfinite(x)) throw CliError("--" + opt + ": " + quoted_text(item) + " is NaN or Inf");
    out.push_back(x);
    start = end + 1;
  }
  return out;
}

VecX state_vector(const Args& a, const std::string& opt, const Model& m) {
  if (!a.has(opt)) return VecX::Zero(m.n());
  const std::vector<double> v = parse_numbers(opt, a.options.at(opt));
  if (static_cast<int>(v.size()) != m.n()) {
    std::string names;
    for (const auto& c : m.coordinate_names) names += (names.empty() ? "" : ", ") + c;
    throw CliError("--" + opt + " has " + std::to_string(v.size()) + " values, expected " +
                   std::to_string(m.n()) + " (" + names + ")");
  }
  return Eigen::Map<const VecX>(v.data(), m.n());
}

VecX configuration_vector(const Args& a, const std::string& opt, const Model& m) {
  if (!a.has(opt)) return neutral_posture(m);
  const std::vector<double> v = parse_numbers(opt, a.options.at(opt));
  if (static_cast<int>(v.size()) != m.n_q()) {
    std::string names;
    for (const auto& c : m.configuration_names) names += (names.empty() ? "" : ", ") + c;
    throw CliError("--" + opt + " has " + std::to_string(v.size()) + " values, expected " +
                   std::to_string(m.n_q()) + " (" + names + ")");
  }
  VecX q = Eigen::Map<const VecX>(v.data(), m.n_q());
  if (const std::string bad = normalize_quaternions(m, q); !bad.empty())
    throw CliError("--" + opt + ": " + bad);
  return q;
}

CommandState command_state(const Args& a, const Model& m) {
  CommandState s{configuration_vector(a, "q", m), state_vector(a, "qd", m),
                 state_vector(a, "tau", m)};
  if (!m.constraints.empty() && !a.has("q"))
    if (const StateAssembly loops = assemble_state(m, s.q, s.qd); !loops.assembly.status.ok)
      throw StateError(a.positional[0] +
                       ": the neutral configuration: " + loops.assembly.status.message);
  return s;
}

double number_option(const Args& a, const std::string& opt, double fallback) {
  if (!a.has(opt)) return fallback;
  const std::vector<double> v = parse_numbers(opt, a.options.at(opt));
  if (v.size() != 1) throw CliError("--" + opt + " expects one number");
  return v[0];
}

double integer_option(const Args& a, const std::string& opt, double fallback, double min,
                      double max) {
  const double v = number_option(a, opt, fallback);
  if (v != std::floor(v) || v < min)
    throw CliError("--" + opt +
                   " expects one integer >= " + std::to_string(static_cast<long>(min)));
  if (v > max) throw CliError("--" + opt + " expects one integer <= " + format_number(max, "%.0f"));
  return v;
}

Model load(const Args& a, std::size_t count) {
  if (a.positional.size() != count)
    throw CliError(count == 1 ? "expected one MODEL file (try --help)"
                              : "expected " + std::to_string(count) + " MODEL files (try --help)");
  return load_model(a.positional[0], load_options(a));
}

Model load_description(const Args& a, std::string& singular) {
  if (a.positional.size() != 1) throw CliError("expected one MODEL file (try --help)");
  LoadOptions opt = load_options(a);
  opt.compile.check_mass = false;
  Model m = load_model(a.positional[0], opt);
  singular.clear();
  if (const auto p = mass_matrix_problem(m, true)) {
    std::string inert;
    for (const std::string& c : p->inert) inert += (inert.empty() ? "'" : ", '") + c + "'";
    singular = p->message + (inert.empty() ? "" : "; moving no inertia at all: " + inert) +
               ": equations, simulate and the other dynamics commands refuse this model";
  }
  return m;
}

double max_memory(const Args& a) {
  if (!a.has("max-memory")) return 0;
  const double gb = number_option(a, "max-memory", 0);
  if (!(gb > 0 && gb < 1e9)) throw CliError("--max-memory expects a positive number of GB");
  return gb * 1e9;
}

LoadOptions load_options(const Args& a) {
  LoadOptions opt;
  opt.warn = [](const std::string& w) {
    std::cerr << "femdyn: warning: " << safe_message(w) << "\n";
  };
  if (a.has("gravity")) {
    const std::vector<double> g = parse_numbers("gravity", a.options.at("gravity"));
    if (g.size() != 3) throw CliError("--gravity expects 3 values gx,gy,gz");
    opt.gravity = Vec3(g[0], g[1], g[2]);
    opt.gravity_source = "--gravity";
  }
  opt.floating_base = a.has("floating-base");
  opt.balance_inertia = a.has("balance-inertia");
  return opt;
}

Args parse_args(int argc, char** argv, int first, const std::vector<std::string>& flags,
                const std::vector<std::string>& valued) {
  Args a;
  for (int i = first; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "-o") s = "--output";  // the one short option
    if (s.rfind("--", 0) != 0) {
      a.positional.push_back(s);
      continue;
    }
    std::string key = s.substr(2), value;
    const auto eq = key.find('=');
    const bool inline_value = eq != std::string::npos;
    if (inline_value) {
      value = key.substr(eq + 1);
      key = key.substr(0, eq);
    }
    // --floating-base, --balance-inertia: every command that loads a model (load_options).
    if (key == "floating-base" || key == "balance-inertia" ||
        std::find(flags.begin(), flags.end(), key) != flags.end()) {
      if (inline_value) throw CliError("--" + key + " takes no value");
      a.options[key] = "";
    } else if (std::find(valued.begin(), valued.end(), key) != valued.end()) {
      if (!inline_value) {
        if (i + 1 >= argc) throw CliError("--" + key + " needs a value");
        value = argv[++i];
      }
      a.options[key] = value;
    } else {
      throw CliError("unknown option --" + escaped(truncated(key)) + " (try --help)");
    }
  }
  return a;
}

int cmd_info(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"}, {"gravity"});
  if (a.has("help")) {
    std::cout << kInfoHelp;
    return 0;
  }
  std::string singular;
  const Model m = load_description(a, singular);
  if (a.has("json")) {
    Json j = info_json(m);
    if (!singular.empty()) j["mass_matrix_singular"] = singular;
    std::cout << json_text(j) << "\n";
  } else {
    std::cout << info_text(m) << (singular.empty() ? "" : "note: " + singular + "\n");
  }
  return 0;
}

int cmd_equations(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json", "tensor"},
                            {"gravity", "q", "qd", "tau", "max-memory"});
  if (a.has("help")) {
    std::cout << kEquationsHelp;
    return 0;
  }
  const Model m = load(a);
  const auto [q, qd, tau] = command_state(a, m);
  require_command_memory(a, "the equations of n = " + std::to_string(m.n()) + " coordinates",
                         equations_bytes(m, a.has("json")));
  Workspace ws(m);
  // q̈ of the mechanism: with closed loops the constrained one, at a state on the loops.
  const std::unique_ptr<LoopWorkspace> loops =
      m.constraints.empty() ? nullptr : std::make_unique<LoopWorkspace>(m);
  const Status st = mechanism_forward_dynamics(m, ws, loops.get(), q, qd, tau);
  evaluate(m, ws, q, qd, tau);
  // A result that overflowed is a fault, never printed as an answer.
  struct Result {
    const char* what;
    const double* data;
    Eigen::Index size, rows;
  };
  for (const Result& x : {Result{"M^s", ws.Ms.data(), ws.Ms.size(), ws.Ms.rows()},
                          Result{"h", ws.h.data(), ws.h.size(), ws.h.size()},
                          Result{"Q", ws.Q.data(), ws.Q.size(), ws.Q.size()},
                          Result{"q̈", ws.qdd.data(), st.ok ? ws.qdd.size() : 0, ws.qdd.size()}})
    for (Eigen::Index i = 0; i < x.size; ++i) {
      if (std::isfinite(x.data[i])) continue;
      std::cerr << "femdyn equations: " << escaped(a.positional[0]) << ": "
                << overflow_text(std::string(x.what) + " of '" + m.coordinate_names[i % x.rows] +
                                 "'")
                << "\n";
      return 1;
    }
  std::vector<MatX> D;
  if (a.has("tensor")) {
    // D has n³ entries and its sweep holds T' (N_u n²): refused before allocating past the limit.
    const double n = m.n(), entries = std::max(n * n * n, m.n_u() * n * n);
    if (entries > kMaxTensorEntries) {
      char buf[160];
      std::snprintf(buf, sizeof buf,
                    "--tensor: D needs %.3g numbers (%.3g GB) for n = %d; the limit is %.3g "
                    "(about n = 150)",
                    entries, entries * 8 / 1e9, m.n(), kMaxTensorEntries);
      throw CliError(buf);
    }
    D = third_order_tensor(m, ws, q);
    evaluate(m, ws, q, qd, tau);  // the tensor sweep reuses the workspace
  }
  if (a.has("json"))
    std::cout << readable_json(equations_json(m, ws, q, qd, tau, st, loops.get(), D));
  else
    std::cout << equations_text(m, ws, q, qd, tau, st, loops.get(), D);
  if (!st.ok) {
    std::cerr << "femdyn equations: " << escaped(a.positional[0]) << ": at this state "
              << safe_message(st.message) << "\n";
    return 1;
  }
  return 0;
}

}  // namespace femdyn::cli
