// femdyn bench MODEL: femdyn's equations of motion timed against the model's Simbody twin
// (validation/twin.hpp, the twin femdyn validate checks against) in the same run: the median
// ns per call of M^s, h, the forces at rest, the whole equations, q̈, τ and D, and on a model
// with loop constraints the constrained q̈ (docs/loops.md), femdyn and Simbody batch by batch in
// turn (docs/benchmarks.md). A URDF robot is also timed on MuJoCo's
// own import of the file (M, q̈, τ) when femdyn is built with MuJoCo (validation/mujoco_peer.hpp).
// The analytic derivatives (core/derivatives/derivatives.hpp) are timed on femdyn alone: neither
// peer has them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <string_view>
#include <vector>

#include "cli/bench_timing.hpp"
#include "cli/commands.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/spatial/math.hpp"
#include "io/output.hpp"
#include "io/urdf_loader.hpp"
#ifdef FEMDYN_WITH_MUJOCO
#include "validation/mujoco_peer.hpp"
#endif
#include "validation/twin.hpp"
#include "validation/validate.hpp"
#include "validation/validate_loops.hpp"

#ifndef FEMDYN_BUILD_TYPE
#define FEMDYN_BUILD_TYPE "unknown"
#endif

namespace femdyn::cli {
namespace {

namespace fv = femdyn::validation;

constexpr const char* kBenchHelp =
    R"(usage: femdyn bench MODEL [--json] [--quick] [--states N] [--gravity gx,gy,gz]

Times femdyn's equations of motion against the model's Simbody twin (the one femdyn validate
compares with) in the same run, and prints for each quantity the median ns per call of both
engines and the ratio Simbody / femdyn (above 1: femdyn is faster):
  M    femdyn: mass_matrix(), M^s alone;
       Simbody: realize Position, calcM
  h    the velocity terms alone, without gravity: femdyn evaluate_bias(); Simbody: realize
       Velocity, the residual with no force and q̈ = 0
  g    gravity and the other state-independent forces (loads, springs) at q̇ = 0: femdyn
       inverse_dynamics(q, 0, 0), which is τ = −Q at rest; Simbody: realize Dynamics at rest,
       the residual with the applied forces and q̈ = 0
  Q    femdyn: evaluate(), M^s, h and Q together (its entry point that assembles Q); Simbody:
       realize Dynamics, calcM and the residual with the applied forces (h − Q)
  qdd  femdyn forward_dynamics(), by the model's route (core/dynamics/equations.hpp); Simbody: realize
       Dynamics, calcAccelerationIgnoringConstraints (calcAcceleration on a coupled model)
  tau  femdyn inverse_dynamics(); Simbody: the residual with the applied forces and q̈
  qdd_c  (a model with loop constraints) the constrained q̈: femdyn
       constrained_forward_dynamics() with Baumgarte off (ω = 0; Simbody has none); Simbody:
       the loop constraints enabled, τ as mobility forces, realize Acceleration (its
       constraint solve). At N states of their own, assembled onto the loops (q near the
       neutral posture, q̇ projected onto Φ_q q̇ = 0), τ in ±1; the other rows keep the
       tree's states
  dtau femdyn inverse_dynamics_derivatives(): ∂τ/∂q and ∂τ/∂v (docs/derivatives.md)
  dqdd femdyn forward_dynamics_derivatives(): q̈, ∂q̈/∂q, ∂q̈/∂v and (M^s)⁻¹
       Both on femdyn alone (Simbody has no derivatives of its dynamics, MuJoCo 2.2 only
       differences its whole time step): the table gives their ratio to femdyn's qdd instead.
       Left out, with a note, on a model the derivatives do not cover.
  D    femdyn third_order_tensor(); Simbody forms no such tensor: n + n(n+1)/2 bias
       evaluations combined by polarization, D_sym(b,c) = (h(e_b+e_c) − h(e_b) − h(e_c))/2,
       the part symmetric in (b, c) (Christoffel symbols). Skipped, for both engines, when
       n > 40 and with --quick (the table says so; with --json, stderr does).
Method: N seeded random states (default 16: q within the joint limits, q̇ in ±2, τ in ±1,
q̈ in ±5), cycled; per engine and quantity a warm-up, then 15 batches of about 20 ms
(--quick: 3 batches of about 2 ms), femdyn and Simbody batches alternating; a batch gives ns
per call, the report is the median, min and max over the batches. Both engines are first
checked to agree on M^s, h and q̈ at the first state, and on the constrained q̈ at the first
assembled state (relative 1e-8; a warning if not; qdd_c is left out, with a warning, where no
state assembles or Simbody cannot pose the loops).
A Debug build refuses to time anything.
MuJoCo: a URDF robot (with --floating-base too) is also timed on MuJoCo's own import of the
file, when femdyn was built with MuJoCo: M (mj_crb, mj_fullM), qdd (mj_forward with the
constraint solver off: its smooth part qacc_smooth) and tau (mj_inverse), in a third column
MuJoCo and the ratio MuJoCo / femdyn; its batches alternate with the other two. Checked first
against femdyn at the first state like Simbody (URDF <dynamics friction>, femdyn's regularised
Coulomb force, is handed to MuJoCo as an applied force there: MuJoCo's frictionloss is a
constraint, off in its smooth dynamics; its timed calls run without it); a file MuJoCo cannot
map (a <mimic> joint) is a warning, and MuJoCo is left out.
--json: {"model", "n", "coordinates", "build", "results": [{"engine": "femdyn" | "simbody" |
"mujoco", "quantity", "median_ns", "min_ns", "max_ns"}]} (n the number of coordinates,
"coordinates" their names; quantity "M", "h", "g", "Q", "qdd", "qdd_c", "tau", "dtau", "dqdd"
or "D"; dtau and dqdd have no "simbody" entry).
)";

constexpr int kTensorMaxN = 40;  // D above this many coordinates takes too long to time

// Timing a Debug build would mislead: refuse (NDEBUG unset, or CMake's build type Debug).
void refuse_debug_build() {
#ifndef NDEBUG
  throw CliError(
      "refusing to time a Debug build (NDEBUG is not defined; build type " FEMDYN_BUILD_TYPE
      "): rebuild with -DCMAKE_BUILD_TYPE=Release");
#endif
  if (std::string_view(FEMDYN_BUILD_TYPE) == "Debug")
    throw CliError(
        "refusing to time a Debug build (build type Debug): rebuild with "
        "-DCMAKE_BUILD_TYPE=Release");
}

// The seeded states the calls cycle through.
struct States {
  std::vector<VecX> q, qd, tau, qdd;
  VecX rest, none;  // q̇ = q̈ = 0; no τ
};

States random_states(const Model& m, int K) {
  States s;
  std::mt19937 rng(1);
  for (int k = 0; k < K; ++k) {
    s.q.push_back(random_posture(m, rng));
    s.qd.push_back(random_uniform(m.n(), 2, rng));
    s.tau.push_back(random_uniform(m.n(), 1, rng));
    s.qdd.push_back(random_uniform(m.n(), 5, rng));
  }
  s.rest = VecX::Zero(m.n());
  return s;
}

// Once, before timing: both engines compute the same M^s, h (evaluate()) and q̈
// (forward_dynamics()) at the first state.
void check_agreement(const std::string& path, const Model& m, Workspace& ws, fv::SimbodyTwin& twin,
                     const States& s) {
  const fv::TwinEquations e = twin.equations(s.q[0], s.qd[0], s.tau[0]);
  const Status st = tree_forward_dynamics(m, ws, s.q[0], s.qd[0], s.tau[0]);
  const double dqdd = st.ok ? relative_error(ws.qdd, e.qdd, 1e-6) : INFINITY;
  evaluate(m, ws, s.q[0], s.qd[0], s.tau[0]);
  const double dM = relative_error(ws.Ms, e.M, 1e-6), dh = relative_error(ws.h, e.h, 1e-6);
  if (dM < 1e-8 && dh < 1e-8 && dqdd < 1e-8) return;
  std::cerr << "femdyn bench: warning: " << escaped(path)
            << ": femdyn and Simbody differ at the first state (relative M^s " << format_short(dM)
            << ", h " << format_short(dh) << ", q̈ "
            << (st.ok ? format_short(dqdd) : "not computed: " + st.message)
            << "); the timings compare different computations\n";
}

// The constrained states (a model with loop constraints): up to K, each assembled onto the loops
// (validation's assembled_state: q a step from the neutral posture, q̇ in ±2 projected onto
// Φ_q q̇ = 0), τ in ±1, each a state where femdyn's constrained dynamics holds (not a dead
// point); up to 4K candidates are tried. `why`: the last reason a candidate was dropped.
struct LoopStates {
  std::vector<VecX> q, qd, tau;
  std::string why;
  int size() const { return static_cast<int>(q.size()); }
};

LoopStates assembled_states(const Model& m, int K) {
  LoopStates s;
  std::mt19937 rng(1);
  Workspace ws(m);
  LoopWorkspace lws(m);
  for (int attempt = 0; attempt < 4 * K && s.size() < K; ++attempt) {
    VecX q, qd;
    if (!fv::assembled_state(m, rng, 2, q, qd, s.why)) continue;
    VecX tau = random_uniform(m.n(), 1, rng);
    const Status st = constrained_forward_dynamics(m, ws, lws, q, qd, tau, 0);
    if (!st.ok) {
      s.why = st.message;
      continue;
    }
    s.q.push_back(std::move(q));
    s.qd.push_back(std::move(qd));
    s.tau.push_back(std::move(tau));
  }
  return s;
}

// Once, before timing: both engines compute the same constrained q̈ at the first assembled
// state. Throws where Simbody cannot pose the loops.
void check_loop_agreement(const std::string& path, const Model& m, fv::SimbodyTwin& twin,
                          const LoopStates& s) {
  const fv::TwinLoopDynamics e = twin.loop_dynamics(s.q[0], s.qd[0], s.tau[0]);
  Workspace ws(m);
  LoopWorkspace lws(m);
  const Status st = constrained_forward_dynamics(m, ws, lws, s.q[0], s.qd[0], s.tau[0], 0);
  const double d = st.ok ? relative_error(ws.qdd, e.qdd, 1e-6) : INFINITY;
  if (d < 1e-8) return;
  std::cerr << "femdyn bench: warning: " << escaped(path)
            << ": femdyn and Simbody differ at the first assembled state (relative constrained q̈ "
            << (st.ok ? format_short(d) : "not computed: " + st.message)
            << "); the timings compare different computations\n";
}

#ifdef FEMDYN_WITH_MUJOCO
// The same for MuJoCo: M^s, q̈ and τ at the first state.
void check_mujoco_agreement(const std::string& path, const Model& m, Workspace& ws,
                            fv::MujocoPeer& peer, const States& s) {
  // MuJoCo has no Coulomb friction in its smooth dynamics (its frictionloss is a constraint, off
  // in the peer): femdyn's is handed to it as an applied force, like with like.
  const VecX friction = coulomb_forces(m, s.qd[0]);
  const Status st = tree_forward_dynamics(m, ws, s.q[0], s.qd[0], s.tau[0]);
  const double dqdd =
      st.ok ? relative_error(peer.forward(s.q[0], s.qd[0], s.tau[0] + friction), ws.qdd, 1e-6)
            : INFINITY;
  inverse_dynamics(m, ws, s.q[0], s.qd[0], s.qdd[0]);
  const double dtau =
      relative_error(peer.inverse(s.q[0], s.qd[0], s.qdd[0]) - friction, ws.tau, 1e-6);
  mass_matrix(m, ws, s.q[0]);
  const double dM = relative_error(peer.mass(s.q[0]), ws.Ms, 1e-6);
  if (dM < 1e-8 && dtau < 1e-8 && dqdd < 1e-8) return;
  std::cerr << "femdyn bench: warning: " << escaped(path)
            << ": femdyn and MuJoCo differ at the first state (relative M^s " << format_short(dM)
            << ", τ " << format_short(dtau) << ", q̈ "
            << (st.ok ? format_short(dqdd) : "not computed: " + st.message)
            << "); the timings compare different computations\n";
}
#endif

// dtau and dqdd (femdyn alone); none, with a note, on a model the derivatives do not cover.
std::vector<Row> time_derivative_rows(const Model& m, Workspace& ws, const States& s, int K,
                                      const Method& method) {
  if (const std::string why = derivatives_unsupported(m); !why.empty()) {
    std::cerr << "femdyn bench: note: dtau and dqdd not timed: " << why << "\n";
    return {};
  }
  DerivativeWorkspace d(m);
  d.baumgarte = 0;  // closed loops: the constrained equations as qdd_c times them (ω = 0)
  std::vector<Row> rows;
  rows.push_back(time_femdyn(
      "dtau",
      [&](int k) {
        inverse_dynamics_derivatives(m, ws, d, s.q[k], s.qd[k], s.qdd[k]);
        keep(d.dtau_dq.data());
      },
      K, method));
  rows.push_back(time_femdyn(
      "dqdd",
      [&](int k) {
        const bool ok = forward_dynamics_derivatives(m, ws, d, s.q[k], s.qd[k], s.tau[k]).ok;
        keep(&ok);
        keep(d.dqdd_dq.data());
      },
      K, method));
  return rows;
}

// qdd_c: femdyn's constrained_forward_dynamics (ω = 0) against Simbody's constrained forward
// dynamics (SimbodyTwin::time_constrained) at the assembled states; nothing, with a warning,
// where no state assembles or Simbody cannot pose the loops.
std::optional<Row> time_constrained_row(const std::string& path, const Model& m,
                                        fv::SimbodyTwin& twin, int K, const Method& method) {
  const LoopStates s = assembled_states(m, K);
  try {
    if (s.size() == 0) throw Error("no state could be assembled onto the loops: " + s.why);
    check_loop_agreement(path, m, twin, s);
    Workspace ws(m);
    LoopWorkspace lws(m);
    return time_both(
        "qdd_c",
        [&](int k) {
          const bool ok = constrained_forward_dynamics(m, ws, lws, s.q[k], s.qd[k], s.tau[k], 0).ok;
          keep(&ok);
          keep(ws.qdd.data());
        },
        [&](int k) { twin.time_constrained(s.q[k], s.qd[k], s.tau[k]); }, s.size(), method);
  } catch (const std::exception& e) {
    std::cerr << "femdyn bench: warning: qdd_c not timed: " << safe_message(e.what()) << "\n";
    return std::nullopt;
  }
}

// Why D is not timed, or empty.
std::string tensor_skipped(int n, bool quick) {
  std::string why;
  if (n > kTensorMaxN) why = "n = " + std::to_string(n) + " > " + std::to_string(kTensorMaxN);
  if (quick) why += (why.empty() ? "" : " and ") + std::string("--quick");
  return why;
}

std::string ns_text(double x) { return format_number(x, "%.0f"); }

// The rows timed on femdyn alone (the derivatives), with their ratio to femdyn's own qdd.
void print_femdyn_only(const std::vector<Row>& rows) {
  const auto qdd =
      std::find_if(rows.begin(), rows.end(), [](const Row& r) { return r.quantity == "qdd"; });
  char line[200];
  bool header = false;
  for (const Row& r : rows) {
    if (r.simbody) continue;
    if (!header) {
      std::snprintf(line, sizeof line, "%-8s %10s %15s   %s\n", "quantity", "femdyn", "femdyn/qdd",
                    "femdyn min-max");
      std::cout << line;
      header = true;
    }
    const std::string ratio =
        qdd == rows.end() ? "-" : format_number(r.femdyn.median / qdd->femdyn.median, "%.2f");
    std::snprintf(line, sizeof line, "%-8s %10s %15s   %s\n", r.quantity.c_str(),
                  ns_text(r.femdyn.median).c_str(), ratio.c_str(),
                  (ns_text(r.femdyn.min) + "-" + ns_text(r.femdyn.max)).c_str());
    std::cout << line;
  }
}

void print_table(const std::string& path, int n, int K, const Method& method,
                 const std::vector<Row>& rows, const std::string& skipped) {
  const bool mujoco = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.mujoco; });
  std::cout << escaped(path) << " (" << n << " coordinates) against Simbody"
            << (mujoco ? " and MuJoCo" : "") << ": median ns per call over " << method.batches
            << " batches of ~" << method.batch_time_ns / 1e6 << " ms, " << K
            << " states, build " FEMDYN_BUILD_TYPE "\n";
  char line[200];
  std::snprintf(line, sizeof line, "%-8s %10s %10s %15s   %-21s %s\n", "quantity", "femdyn",
                "Simbody", "Simbody/femdyn", "femdyn min-max", "Simbody min-max");
  std::cout << line;
  for (const Row& r : rows) {
    if (!r.simbody) continue;
    const std::string fr = ns_text(r.femdyn.min) + "-" + ns_text(r.femdyn.max);
    const std::string sr = ns_text(r.simbody->min) + "-" + ns_text(r.simbody->max);
    std::snprintf(line, sizeof line, "%-8s %10s %10s %15s   %-21s %s\n", r.quantity.c_str(),
                  ns_text(r.femdyn.median).c_str(), ns_text(r.simbody->median).c_str(),
                  format_number(r.simbody->median / r.femdyn.median, "%.2f").c_str(), fr.c_str(),
                  sr.c_str());
    std::cout << line;
  }
  if (mujoco) {
    std::snprintf(line, sizeof line, "%-8s %10s %10s %15s   %s\n", "quantity", "femdyn", "MuJoCo",
                  "MuJoCo/femdyn", "MuJoCo min-max");
    std::cout << line;
    for (const Row& r : rows) {
      if (!r.mujoco) continue;
      std::snprintf(line, sizeof line, "%-8s %10s %10s %15s   %s\n", r.quantity.c_str(),
                    ns_text(r.femdyn.median).c_str(), ns_text(r.mujoco->median).c_str(),
                    format_number(r.mujoco->median / r.femdyn.median, "%.2f").c_str(),
                    (ns_text(r.mujoco->min) + "-" + ns_text(r.mujoco->max)).c_str());
      std::cout << line;
    }
  }
  print_femdyn_only(rows);
  if (!skipped.empty()) std::cout << "D        skipped (" << skipped << ")\n";
}

nlohmann::ordered_json report_json(const std::string& path, const Model& m,
                                   const std::vector<Row>& rows) {
  nlohmann::ordered_json results = nlohmann::ordered_json::array();
  auto add = [&](const char* engine, const std::string& quantity, const Timing& t) {
    results.push_back({{"engine", engine},
                       {"quantity", quantity},
                       {"median_ns", t.median},
                       {"min_ns", t.min},
                       {"max_ns", t.max}});
  };
  for (const Row& r : rows) {
    add("femdyn", r.quantity, r.femdyn);
    if (r.simbody) add("simbody", r.quantity, *r.simbody);
    if (r.mujoco) add("mujoco", r.quantity, *r.mujoco);
  }
  return {{"model", path},
          {"n", m.n()},
          {"coordinates", m.coordinate_names},
          {"build", FEMDYN_BUILD_TYPE},
          {"results", results}};
}

// The Simbody twin the rows are timed against (its errors, which span lines, in one line).
std::unique_ptr<fv::SimbodyTwin> bench_twin(const Model& m, const std::string& path) {
  std::unique_ptr<fv::SimbodyTwin> twin;
  try {
    twin = std::make_unique<fv::SimbodyTwin>(fv::twin_model(m));
  } catch (const std::exception& e) {  // Simbody's messages span lines: one line here
    std::istringstream words(e.what());
    std::string why, word;
    while (words >> word) why += (why.empty() ? "" : " ") + word;
    throw ModelError(path, "Simbody refused the twin: " + why);
  }
  return twin;
}

// MuJoCo's calls for M, qdd and tau (none: not a URDF robot, or built without MuJoCo).
struct MujocoCalls {
  std::function<void(int)> mass, forward, inverse;
};

// Every row: M, h, g, Q, q̈, the constrained q̈ of a closed model, τ, the derivatives (femdyn
// alone) and D unless `skipped` says why not.
std::vector<Row> time_rows(const std::string& path, const Model& m, Workspace& ws,
                           fv::SimbodyTwin& twin, const States& s, int K, const Method& method,
                           const MujocoCalls& mj, const std::string& skipped) {
  std::vector<Row> rows;
  // M^s: femdyn's mass_matrix (M^s alone) / Simbody's calcM at Position.
  rows.push_back(time_both(
      "M",
      [&](int k) {
        mass_matrix(m, ws, s.q[k]);
        keep(ws.Ms.data());
      },
      [&](int k) { twin.time_mass(s.q[k]); }, K, method, mj.mass));
  // h without gravity: velocity terms alone.
  rows.push_back(time_both(
      "h",
      [&](int k) {
        evaluate_bias(m, ws, s.q[k], s.qd[k]);
        keep(ws.h.data());
      },
      [&](int k) { twin.time_bias(s.q[k], s.qd[k]); }, K, method));
  // Gravity and the other state-independent forces at rest: τ = −Q(q̇ = 0).
  rows.push_back(time_both(
      "g",
      [&](int k) {
        inverse_dynamics(m, ws, s.q[k], s.rest, s.rest);
        keep(ws.tau.data());
      },
      [&](int k) { twin.time_gravity(s.q[k]); }, K, method));
  // Q: femdyn assembles it in evaluate() with M^s and h; Simbody calcM + residual (h − Q).
  rows.push_back(time_both(
      "Q",
      [&](int k) {
        evaluate(m, ws, s.q[k], s.qd[k], s.tau[k]);
        keep(ws.Q.data());
      },
      [&](int k) { twin.time_mass_and_bias(s.q[k], s.qd[k]); }, K, method));
  // q̈: forward dynamics.
  rows.push_back(time_both(
      "qdd",
      [&](int k) {
        tree_forward_dynamics(m, ws, s.q[k], s.qd[k], s.tau[k]);
        keep(ws.qdd.data());
      },
      [&](int k) { twin.time_forward(s.q[k], s.qd[k], s.tau[k]); }, K, method, mj.forward));
  // Constrained q̈ (a model with loop constraints), at states assembled onto the loops.
  if (!m.constraints.empty())
    if (std::optional<Row> row = time_constrained_row(path, m, twin, K, method))
      rows.push_back(std::move(*row));
  // τ: inverse dynamics.
  rows.push_back(time_both(
      "tau",
      [&](int k) {
        inverse_dynamics(m, ws, s.q[k], s.qd[k], s.qdd[k]);
        keep(ws.tau.data());
      },
      [&](int k) { twin.time_inverse(s.q[k], s.qd[k], s.qdd[k]); }, K, method, mj.inverse));
  // The analytic derivatives, femdyn alone.
  for (Row& row : time_derivative_rows(m, ws, s, K, method)) rows.push_back(std::move(row));
  // D: femdyn's tensor / Simbody's symmetric part by polarization of h.
  if (skipped.empty())
    rows.push_back(time_both(
        "D",
        [&](int k) {
          const std::vector<MatX> D = third_order_tensor(m, ws, s.q[k]);
          keep(D.data());
        },
        [&](int k) { twin.time_tensor(s.q[k]); }, K, method));
  return rows;
}

}  // namespace

int cmd_bench(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json", "quick"}, {"states", "gravity"});
  if (a.has("help")) {
    std::cout << kBenchHelp;
    return 0;
  }
  // (the command line's errors first, exit 2, whatever the build)
  if (a.positional.size() != 1) throw CliError("expected one MODEL file (try --help)");
  refuse_debug_build();
  const int K = static_cast<int>(integer_option(a, "states", 16, 1, 10000));
  const Model m = load(a);
  const std::string& path = a.positional[0];
  const int n = m.n();
  if (n == 0) throw ModelError(path, "the model has no coordinates: nothing to time");
  const bool quick = a.has("quick");
  const Method method = quick ? Method{3, 2e6} : Method{};

  const std::unique_ptr<fv::SimbodyTwin> twin = bench_twin(m, path);
  Workspace ws(m);
  const States s = random_states(m, K);
  check_agreement(path, m, ws, *twin, s);
  MujocoCalls mj;
#ifdef FEMDYN_WITH_MUJOCO
  std::unique_ptr<fv::MujocoPeer> peer;
  std::vector<fv::MujocoPeer::State> mj_states;
  if (is_urdf_path(path)) {
    try {
      peer = std::make_unique<fv::MujocoPeer>(path, m.gravity, a.has("floating-base"),
                                              m.coordinate_names);
      check_mujoco_agreement(path, m, ws, *peer, s);
      for (int k = 0; k < K; ++k)
        mj_states.push_back(peer->state(s.q[k], s.qd[k], s.tau[k], s.qdd[k]));
      mj.mass = [&](int k) { peer->time_mass(mj_states[k]); };
      mj.forward = [&](int k) { peer->time_forward(mj_states[k]); };
      mj.inverse = [&](int k) { peer->time_inverse(mj_states[k]); };
    } catch (const std::runtime_error& e) {
      std::cerr << "femdyn bench: warning: MuJoCo not timed: " << safe_message(e.what()) << "\n";
    }
  }
#endif

  const std::string skipped = tensor_skipped(n, quick);
  const std::vector<Row> rows = time_rows(path, m, ws, *twin, s, K, method, mj, skipped);
  if (a.has("json")) {
    if (!skipped.empty()) std::cerr << "femdyn bench: D not timed (" << skipped << ")\n";
    std::cout << json_text(report_json(path, m, rows)) << "\n";
  } else {
    print_table(path, n, K, method, rows, skipped);
  }
  return 0;
}

}  // namespace femdyn::cli
