// femdyn_bench: femdyn's equations against Simbody's on the same mechanisms (docs/benchmarks.md,
// docs/performance.md, generated from it by tools/update-performance-docs.sh).
//
// For each bundled model, hand16, the KUKA iiwa, HyQ and Atlas (welded, and HyQ and Atlas on a
// floating base: hyq_floating, atlas_floating), a seeded random 20-DOF chain and random chains
// and trees of --sizes= bodies (default 8 to 1024), at one seeded state:
//   femdyn/mass/M       mass_matrix(): M^s alone     simbody/mass/M      calcM
//   femdyn/evaluate/M   evaluate(): M^s, h, Q          simbody/evaluate/M  calcM + residual (h − Q)
//   femdyn/bias/M       evaluate_bias(): h             simbody/bias/M      residual, no forces (h)
//   femdyn/forward/M    forward_dynamics(): q̈
//   simbody/forward/M   calcAccelerationIgnoringConstraints
//   femdyn/inverse/M    inverse_dynamics(): τ
//   femdyn/derivatives/M forward_dynamics_derivatives(): q̈, ∂q̈/∂q, ∂q̈/∂v and M⁻¹ (models the
//                       analytic derivatives cover, core/derivatives/derivatives.hpp)
//   femdyn/inverse_derivatives/M  inverse_dynamics_derivatives(): ∂τ/∂q and ∂τ/∂v alone
//   simbody/inverse/M   residual with θ̈
//   femdyn/rest/M       evaluate() at q̇ = 0 (h not computed)
//   femdyn/weightless/M evaluate() on the model without gravity (models with gravity only)
//   mujoco/mass/M       mj_kinematics, mj_comPos, mj_crb, mj_fullM (URDF robots, when built
//   mujoco/inverse/M    mj_inverse                  with MuJoCo: validation/mujoco_peer.hpp)
//   mujoco/forward/M    mj_forward, constraints off (qacc = qacc_smooth)
//   femdyn/forward/finger_fourbar, femdyn/constrained/finger_fourbar_loop: the finger's
//   four-bar closed by its coupling law and by a loop constraint (register_fourbar_routes).
//   femdyn/constrained/M   constrained_forward_dynamics(), ω = 0, on the closed-loop models
//   simbody/constrained/M  time_constrained: loops enabled, realize Acceleration (add_loop_case)
//   */constrained/loop_chainN: a random chain of --sizes= bodies held at its tip by a ball, and
//   reference/constrained/loop_chainN on the Cholesky route (add_loop_chain), for the growth
//   reference/{mass,bias,forward,inverse}/M: femdyn on the reference routes (Tᵀ M T, node-level
//   sweeps, Cholesky) where n ≤ 128, for the crossovers.
// and, for the growth of loading with n, on generated chains and binary trees of --load-sizes=
// bodies (default 1,000 to 200,000) with one lumped point each (validation/scaling_models.hpp):
//   load/chain/N, load/tree/N  load_model() of the JSON file: read, parse, compile; counter
//                              peak_MB, the peak resident memory loading added to the process.
// Simbody's side is SimbodyTwin::time_* (validation/twin.hpp): its own work only; MuJoCo's is
// MujocoPeer::time_* on the URDF as MuJoCo imports it, its state set in its own coordinates
// outside the timing. This file does not include Simbody or MuJoCo, so it is compiled like the
// rest of femdyn (C++20, NDEBUG).
// Exits 1 if an engine disagrees with Simbody (or MuJoCo) or femdyn allocates in a timed call.
//
// Heap allocations are counted (validation/alloc_counter.hpp) and reported per iteration as the
// counter `allocs`; femdyn's hot path is documented allocation-free and must show 0.
#include <benchmark/benchmark.h>
#include <malloc.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "compile/compile.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/spatial/math.hpp"
#include "models/model_files.hpp"
#include "validation/alloc_counter.hpp"
#ifdef FEMDYN_WITH_MUJOCO
#include "validation/mujoco_peer.hpp"
#endif
#include "validation/scaling_models.hpp"
#include "validation/twin.hpp"
#include "validation/validate.hpp"
#include "validation/validate_loops.hpp"

namespace {

using namespace femdyn;
namespace fv = femdyn::validation;

struct Case {
  std::string name;
  Model model;
  std::unique_ptr<Workspace> ws;
  std::unique_ptr<fv::SimbodyTwin> twin;
#ifdef FEMDYN_WITH_MUJOCO
  std::unique_ptr<fv::MujocoPeer> mujoco;  // URDF robots only
  fv::MujocoPeer::State mujoco_state;      // the state above in MuJoCo's coordinates
#endif
  VecX q, qd, tau, qdd, rest;  // rest: q̇ = 0
  // The same mechanism on the reference routes (Tᵀ M T, node-level sweeps, Cholesky), for the
  // crossovers in docs/performance.md; up to 128 coordinates (Tᵀ M T is O(N_u n²)).
  std::unique_ptr<const Model> reference;
  std::unique_ptr<Workspace> ws_ref;
  // The same mechanism without gravity (when it has some): "leave out what the scene does not
  // need" measured, against evaluate() with gravity.
  std::unique_ptr<const Model> weightless;
  std::unique_ptr<Workspace> ws_weightless;
  std::unique_ptr<DerivativeWorkspace>
      derivatives;  // where core/derivatives/derivatives.hpp covers it
};

// What makes the run fail (exit 1): engines that disagree, femdyn allocating in its hot path.
// (The reference routes are not held to that: Eigen's large dense products allocate.)
std::set<std::string>& failures() {
  static std::set<std::string> all;
  return all;
}

std::vector<std::unique_ptr<Case>>& cases() {
  static std::vector<std::unique_ptr<Case>> all;
  return all;
}

// A URDF robot's file, for MuJoCo's own import of it (empty: not a URDF robot).
struct Urdf {
  std::string path;
  bool floating = false;
};

// The state of femdyn validate's first sample: seed 1, q within the joint limits,
// q̇ in ±2, τ in ±1, q̈ in ±5. Checks once, outside the timing, that the engines agree.
template <class Spec>
void add_case(std::string name, Spec spec, const Urdf& urdf = {}) {
  auto c = std::make_unique<Case>();
  c->name = std::move(name);
  c->model = compile(spec());
  const Model& m = c->model;
  if (!m.gravity.isZero()) {
    MechanismSpec s = spec();
    s.gravity = Vec3::Zero();
    c->weightless = std::make_unique<const Model>(compile(std::move(s)));
    c->ws_weightless = std::make_unique<Workspace>(*c->weightless);
  }
  if (m.n() <= 128) {
    c->reference = std::make_unique<const Model>(
        compile(spec(), {.routes = {.mass = MassRoute::Transform,
                                    .force = ForceRoute::Nodes,
                                    .dynamics = DynamicsRoute::Cholesky}}));
    c->ws_ref = std::make_unique<Workspace>(*c->reference);
  }
  c->ws = std::make_unique<Workspace>(m);
  if (derivatives_unsupported(m).empty()) c->derivatives = std::make_unique<DerivativeWorkspace>(m);
  c->twin = std::make_unique<fv::SimbodyTwin>(fv::twin_model(m));
  std::mt19937 rng(1);
  c->q = random_posture(m, rng);
  c->qd = random_uniform(m.n(), 2, rng);
  c->tau = random_uniform(m.n(), 1, rng);
  c->qdd = random_uniform(m.n(), 5, rng);
  c->rest = VecX::Zero(m.n());

  const fv::TwinEquations s = c->twin->equations(c->q, c->qd, c->tau);
  const bool ok = forward_dynamics(m, *c->ws, c->q, c->qd, c->tau).ok;
  evaluate(m, *c->ws, c->q, c->qd, c->tau);  // M^s, h, Q (the articulated route forms none)
  const double e =
      std::max({relative_error(c->ws->Ms, s.M, 1e-6), relative_error(c->ws->h, s.h, 1e-6),
                relative_error(c->ws->Q, s.Q, 1e-6),
                ok ? relative_error(c->ws->qdd, s.qdd, 1e-6) : INFINITY});
  if (!(e < 1e-8)) {  // timing two engines that disagree would mean nothing
    std::fprintf(stderr, "femdyn_bench: %s: femdyn and Simbody differ (relative %.3g)\n",
                 c->name.c_str(), e);
    failures().insert(c->name + ": femdyn and Simbody differ");
  }
#ifdef FEMDYN_WITH_MUJOCO
  if (!urdf.path.empty()) {
    c->mujoco =
        std::make_unique<fv::MujocoPeer>(urdf.path, m.gravity, urdf.floating, m.coordinate_names);
    fv::MujocoPeer& p = *c->mujoco;
    double e_mj = INFINITY;
    if (forward_dynamics(m, *c->ws, c->q, c->qd, c->tau).ok)
      e_mj = relative_error(p.forward(c->q, c->qd, c->tau), c->ws->qdd, 1e-6);
    inverse_dynamics(m, *c->ws, c->q, c->qd, c->qdd);
    e_mj = std::max(e_mj, relative_error(p.inverse(c->q, c->qd, c->qdd), c->ws->tau, 1e-6));
    mass_matrix(m, *c->ws, c->q);
    e_mj = std::max(e_mj, relative_error(p.mass(c->q), c->ws->Ms, 1e-6));
    if (!(e_mj < 1e-8)) {
      std::fprintf(stderr, "femdyn_bench: %s: femdyn and MuJoCo differ (relative %.3g)\n",
                   c->name.c_str(), e_mj);
      failures().insert(c->name + ": femdyn and MuJoCo differ");
    }
    c->mujoco_state = p.state(c->q, c->qd, c->tau, c->qdd);
  }
#endif
  cases().push_back(std::move(c));
}

// Runs `body` in the timing loop with allocation counting on; `allocs` = heap allocations per
// iteration (a warm-up call first, so buffers sized on first use are not counted).
template <class Body>
void timed(benchmark::State& state, int n, const std::string& name, bool femdyn, Body&& body) {
  body();
  long allocs = 0;
  for (auto _ : state) {
    alloc_counter::start();
    body();
    allocs += alloc_counter::stop();
    benchmark::ClobberMemory();
  }
  state.counters["n"] = n;
  state.counters["allocs"] =
      state.iterations() ? static_cast<double>(allocs) / static_cast<double>(state.iterations())
                         : 0;
  if (femdyn && allocs > 0) failures().insert(name + ": femdyn allocated");
}

void register_case(Case* c) {
  const std::string& name = c->name;
  auto reg = [&](const std::string& lib, const std::string& op, auto fn) {
    const std::string full = lib + "/" + op + "/" + name;
    benchmark::RegisterBenchmark(full.c_str(), [c, fn, full, lib](benchmark::State& st) {
      timed(st, c->model.n(), full, lib == "femdyn", [&] { fn(*c); });
    })->Unit(benchmark::kMicrosecond);
  };
  // femdyn, Simbody and MuJoCo alternate, so drifts of a noisy machine hit them alike.
  const auto reg_mujoco = [&](const std::string& op) {
#ifdef FEMDYN_WITH_MUJOCO
    if (!c->mujoco) return;
    if (op == "mass") reg("mujoco", op, [](Case& c) { c.mujoco->time_mass(c.mujoco_state); });
    if (op == "inverse") reg("mujoco", op, [](Case& c) { c.mujoco->time_inverse(c.mujoco_state); });
    if (op == "forward") reg("mujoco", op, [](Case& c) { c.mujoco->time_forward(c.mujoco_state); });
#endif
  };
  reg("femdyn", "mass", [](Case& c) { mass_matrix(c.model, *c.ws, c.q); });
  reg("simbody", "mass", [](Case& c) { c.twin->time_mass(c.q); });
  reg_mujoco("mass");
  reg("femdyn", "evaluate", [](Case& c) { evaluate(c.model, *c.ws, c.q, c.qd, c.tau); });
  reg("simbody", "evaluate", [](Case& c) { c.twin->time_mass_and_bias(c.q, c.qd); });
  reg("femdyn", "rest", [](Case& c) { evaluate(c.model, *c.ws, c.q, c.rest, c.tau); });
  if (c->weightless)
    reg("femdyn", "weightless",
        [](Case& c) { evaluate(*c.weightless, *c.ws_weightless, c.q, c.qd, c.tau); });
  reg("femdyn", "bias", [](Case& c) { evaluate_bias(c.model, *c.ws, c.q, c.qd); });
  reg("simbody", "bias", [](Case& c) { c.twin->time_bias(c.q, c.qd); });
  reg("femdyn", "forward", [](Case& c) {
    benchmark::DoNotOptimize(forward_dynamics(c.model, *c.ws, c.q, c.qd, c.tau).ok);
  });
  reg("simbody", "forward", [](Case& c) { c.twin->time_forward(c.q, c.qd, c.tau); });
  reg_mujoco("forward");
  if (c->derivatives)
    reg("femdyn", "derivatives", [](Case& c) {
      benchmark::DoNotOptimize(
          forward_dynamics_derivatives(c.model, *c.ws, *c.derivatives, c.q, c.qd, c.tau).ok);
    });
  if (c->derivatives)
    reg("femdyn", "inverse_derivatives", [](Case& c) {
      inverse_dynamics_derivatives(c.model, *c.ws, *c.derivatives, c.q, c.qd, c.qdd);
    });
  reg("femdyn", "inverse", [](Case& c) { inverse_dynamics(c.model, *c.ws, c.q, c.qd, c.qdd); });
  reg("simbody", "inverse", [](Case& c) { c.twin->time_inverse(c.q, c.qd, c.qdd); });
  reg_mujoco("inverse");
  if (!c->reference) return;
  reg("reference", "mass", [](Case& c) { mass_matrix(*c.reference, *c.ws_ref, c.q); });
  reg("reference", "bias", [](Case& c) { evaluate_bias(*c.reference, *c.ws_ref, c.q, c.qd); });
  reg("reference", "forward", [](Case& c) {
    benchmark::DoNotOptimize(forward_dynamics(*c.reference, *c.ws_ref, c.q, c.qd, c.tau).ok);
  });
  reg("reference", "inverse",
      [](Case& c) { inverse_dynamics(*c.reference, *c.ws_ref, c.q, c.qd, c.qdd); });
}

// Memory a load takes: the process's peak resident memory while loading above what it held
// before (Linux: VmHWM and VmRSS of /proc/self/status; the peak is reset by writing 5 to
// /proc/self/clear_refs). In MB; 0 where unavailable.
double status_mb(const char* field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(field, 0) == 0) return std::stod(line.substr(std::strlen(field))) / 1024.0;
  return 0;
}

double reset_peak_memory() {  // returns the resident memory before the load
  malloc_trim(0);             // (what earlier benchmarks freed goes back to the system first)
  std::ofstream("/proc/self/clear_refs") << "5";
  return status_mb("VmRSS:");
}

// load/KIND/N: load_model() of a generated file of N bodies (written once, outside the timing,
// and removed afterwards); counter peak_MB, the peak resident memory the loads added.
void register_load(bool tree, int bodies) {
  const std::string name =
      std::string("load/") + (tree ? "tree" : "chain") + "/" + std::to_string(bodies);
  benchmark::RegisterBenchmark(name.c_str(), [tree, bodies, name](benchmark::State& state) {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("femdyn_bench_" + std::to_string(getpid()) + "_" + std::to_string(bodies) + ".json");
    std::ofstream(path) << scaling::model_json(bodies, tree);
    const double before = reset_peak_memory();
    try {
      for (auto _ : state) benchmark::DoNotOptimize(load_model(path.string()).n());
    } catch (const std::exception& e) {
      failures().insert(name + ": " + e.what());
      state.SkipWithError("the model did not load");
    }
    std::filesystem::remove(path);
    state.counters["n"] = bodies;
    state.counters["peak_MB"] = status_mb("VmHWM:") - before;
  })->Unit(benchmark::kMillisecond);
}

// The finger's four-bar closed two ways (issue 25, item 6), one forward dynamics each at the same
// state of the same mechanism (tests/test_parallel_robots.cpp shows that they move alike):
//   femdyn/forward/finger_fourbar          the four_bar coupling law: forward_dynamics(), n = 3
//   femdyn/constrained/finger_fourbar_loop the loop closed by a constraint (its coupler a body):
//                                          constrained_forward_dynamics(), n = 5, 2 equations,
//                                          ω = 0
struct FourBarRoutes {
  Model law, loop;
  std::unique_ptr<Workspace> ws_law, ws_loop;
  std::unique_ptr<LoopWorkspace> lws;
  VecX q_law, v_law, tau_law, q_loop, v_loop, tau_loop;
};

FourBarRoutes& fourbar_routes() {
  static FourBarRoutes r;  // outlives the benchmarks
  return r;
}

void register_fourbar_routes(const std::string& root) {
  static FourBarRoutes& r = fourbar_routes();  // (static: the benchmarks' lambdas use it)
  r.law = load_model(root + "models/finger_fourbar.json");
  r.loop = load_model(root + "models/finger_fourbar_loop.json");
  r.ws_law = std::make_unique<Workspace>(r.law);
  r.ws_loop = std::make_unique<Workspace>(r.loop);
  r.lws = std::make_unique<LoopWorkspace>(r.loop);
  r.q_law = (VecX(3) << 0.1, 0.3, 0.5).finished();
  r.v_law = (VecX(3) << 0.5, -1.0, 1.0).finished();
  r.tau_law = (VecX(3) << 2e-4, -1e-4, 5e-5).finished();
  // The loop's state: the same three coordinates, dip and the coupler assembled, their rates
  // from Φ_q v = 0.
  r.q_loop = (VecX(5) << r.q_law, 0.5 * 2 / 3, 0).finished();
  if (!assemble(r.loop, *r.ws_loop, r.lws->k, r.q_loop, {.held = {0, 1, 2}}).status.ok)
    throw std::runtime_error("finger_fourbar_loop.json: the start did not assemble");
  r.v_loop = (VecX(5) << r.v_law, 0, 0).finished();
  constraint_kinematics(r.loop, *r.ws_loop, r.q_loop, r.v_loop, r.lws->k);
  const Eigen::Matrix2d Jd = r.lws->k.J.rightCols(2);
  r.v_loop.tail(2) = Jd.partialPivLu().solve(-r.lws->k.J.leftCols(3) * r.v_law);
  r.tau_loop = (VecX(5) << r.tau_law, 0, 0).finished();
  const auto reg = [](const std::string& name, int n, auto body) {
    benchmark::RegisterBenchmark(name.c_str(), [name, n, body](benchmark::State& state) {
      timed(state, n, name, true, body);
    })->Unit(benchmark::kMicrosecond);
  };
  reg("femdyn/forward/finger_fourbar", 3, [] {
    benchmark::DoNotOptimize(forward_dynamics(r.law, *r.ws_law, r.q_law, r.v_law, r.tau_law).ok);
  });
  reg("femdyn/constrained/finger_fourbar_loop", 5, [] {
    benchmark::DoNotOptimize(
        constrained_forward_dynamics(r.loop, *r.ws_loop, *r.lws, r.q_loop, r.v_loop, r.tau_loop, 0)
            .ok);
  });
}

// A closed-loop model's constrained forward dynamics on both engines, at one state:
//   femdyn/constrained/M   constrained_forward_dynamics(), Baumgarte off (ω = 0: Simbody has
//                          none)
//   simbody/constrained/M  SimbodyTwin::time_constrained: the loop constraints enabled, τ as
//                          mobility forces, realize Acceleration (its constraint solve)
// The state is assembled onto the loops (validation's assembled_state, seed 1: q a step from
// the neutral posture, q̇ in ±2 projected onto Φ_q q̇ = 0; τ in ±1), or given; the engines are
// checked once, outside the timing, to agree on the constrained q̈ (relative 1e-8).
struct LoopCase {
  std::string name;
  Model model;
  std::unique_ptr<Workspace> ws;
  std::unique_ptr<LoopWorkspace> lws;
  std::unique_ptr<fv::SimbodyTwin> twin;
  VecX q, qd, tau;
  bool femdyn = true;  // false: femdyn's side is registered elsewhere (register_fourbar_routes)
  bool simbody = true;
  // The same mechanism on the Cholesky route (M^s formed and factorised), for the growth with n.
  std::unique_ptr<const Model> reference;
  std::unique_ptr<Workspace> ws_ref;
  std::unique_ptr<LoopWorkspace> lws_ref;
};

std::vector<std::unique_ptr<LoopCase>>& loop_cases() {
  static std::vector<std::unique_ptr<LoopCase>> all;
  return all;
}

struct LoopState {
  VecX q, qd, tau;
};

LoopState assembled_loop_state(const Model& m, const std::string& name) {
  std::mt19937 rng(1);
  LoopState s;
  std::string why;
  if (!fv::assembled_state(m, rng, 2, s.q, s.qd, why))
    throw std::runtime_error(name + ": no state assembled onto the loops: " + why);
  s.tau = random_uniform(m.n(), 1, rng);
  return s;
}

void check_loop_case(LoopCase& c) {
  const Status st = constrained_forward_dynamics(c.model, *c.ws, *c.lws, c.q, c.qd, c.tau, 0);
  const fv::TwinLoopDynamics s = c.twin->loop_dynamics(c.q, c.qd, c.tau);
  const double e = st.ok ? relative_error(c.ws->qdd, s.qdd, 1e-6) : INFINITY;
  if (!(e < 1e-8)) {
    std::fprintf(stderr,
                 "femdyn_bench: %s: femdyn and Simbody differ on the constrained q̈ "
                 "(relative %.3g)\n",
                 c.name.c_str(), e);
    failures().insert(c.name + ": femdyn and Simbody differ (constrained)");
  }
}

// `state` given: that state (assembled by the caller); else assembled_loop_state.
void add_loop_case(const std::string& name, const std::string& path,
                   const LoopState* state = nullptr, bool femdyn = true) {
  auto c = std::make_unique<LoopCase>();
  c->name = name;
  c->model = load_model(path);
  c->ws = std::make_unique<Workspace>(c->model);
  c->lws = std::make_unique<LoopWorkspace>(c->model);
  c->twin = std::make_unique<fv::SimbodyTwin>(fv::twin_model(c->model));
  const LoopState s = state ? *state : assembled_loop_state(c->model, name);
  c->q = s.q, c->qd = s.qd, c->tau = s.tau;
  c->femdyn = femdyn;
  check_loop_case(*c);
  loop_cases().push_back(std::move(c));
}

void register_loop_case(LoopCase* c) {
  const auto reg = [c](const std::string& lib, auto fn) {
    const std::string full = lib + "/constrained/" + c->name;
    benchmark::RegisterBenchmark(full.c_str(), [c, fn, full, lib](benchmark::State& st) {
      timed(st, c->model.n(), full, lib == "femdyn", [&] { fn(*c); });
    })->Unit(benchmark::kMicrosecond);
  };
  if (c->femdyn)
    reg("femdyn", [](LoopCase& c) {
      benchmark::DoNotOptimize(
          constrained_forward_dynamics(c.model, *c.ws, *c.lws, c.q, c.qd, c.tau, 0).ok);
    });
  if (c->simbody) reg("simbody", [](LoopCase& c) { c.twin->time_constrained(c.q, c.qd, c.tau); });
  if (c->reference)
    reg("reference", [](LoopCase& c) {
      benchmark::DoNotOptimize(
          constrained_forward_dynamics(*c.reference, *c.ws_ref, *c.lws_ref, c.q, c.qd, c.tau, 0)
              .ok);
    });
}

// Growth with n at a fixed number of equations: femdyn/constrained/loop_chainN, a random chain
// of N bodies (random_spec, seed 3) whose last body's origin is held by a ball (3 equations) on
// the world where it is at the neutral posture; reference/constrained/loop_chainN the same on
// the Cholesky route (M^s formed and factorised by the tree LTDL) up to 256 bodies; Simbody up
// to 64 (its constrained solve forms an n × n matrix). At the neutral posture with q̇ in ±2
// projected onto the loop, τ in ±1; both routes checked to agree (relative 1e-8).
MechanismSpec random_spec(int seed, int bodies, double branching);

void add_loop_chain(int bodies) {
  MechanismSpec spec = random_spec(3, bodies, 0);
  const Model tree = compile(spec);
  Workspace wt(tree);
  const VecX q = neutral_posture(tree);
  propagate(tree, wt, q, VecX::Zero(tree.n()), {.jacobian = false, .bias = false, .rows = false});
  ConstraintSpec ball{.name = "tip", .type = "ball"};
  ball.a.body = spec.bodies.back().name;
  ball.b.body = "world";
  ball.b.xyz = wt.origin + wt.body.back().p;
  spec.constraints.push_back(ball);
  auto c = std::make_unique<LoopCase>();
  c->name = "loop_chain" + std::to_string(bodies);
  c->model = compile(spec);
  c->ws = std::make_unique<Workspace>(c->model);
  c->lws = std::make_unique<LoopWorkspace>(c->model);
  c->simbody = bodies <= 64;
  if (c->simbody) c->twin = std::make_unique<fv::SimbodyTwin>(fv::twin_model(c->model));
  std::mt19937 rng(1);
  c->q = q;
  c->qd = random_uniform(c->model.n(), 2, rng);
  c->tau = random_uniform(c->model.n(), 1, rng);
  if (const StateAssembly a = assemble_state(c->model, c->q, c->qd); !a.assembly.status.ok)
    throw std::runtime_error(c->name + ": " + a.assembly.status.message);
  if (bodies <= 256) {
    c->reference = std::make_unique<const Model>(
        compile(spec, {.routes = {.dynamics = DynamicsRoute::Cholesky}}));
    c->ws_ref = std::make_unique<Workspace>(*c->reference);
    c->lws_ref = std::make_unique<LoopWorkspace>(*c->reference);
    const Status a =
        constrained_forward_dynamics(c->model, *c->ws, *c->lws, c->q, c->qd, c->tau, 0);
    const Status b = constrained_forward_dynamics(*c->reference, *c->ws_ref, *c->lws_ref, c->q,
                                                  c->qd, c->tau, 0);
    if (!a.ok || !b.ok || !(relative_error(c->ws->qdd, c->ws_ref->qdd, 1e-6) < 1e-8))
      failures().insert(c->name + ": the articulated and Cholesky routes differ");
  }
  if (c->simbody) check_loop_case(*c);
  loop_cases().push_back(std::move(c));
}

// The closed-loop models. finger_fourbar_loop at register_fourbar_routes' state (that of its law
// route), whose femdyn/constrained/finger_fourbar_loop is femdyn's side; hand_fourbar_loop
// (the hand's fingers closed by constraints instead of their four-bar laws) beside its law
// model hand_fourbar.
void add_loop_cases(const std::string& root) {
  for (const char* name : {"delta", "andrews", "five_bar"})
    add_loop_case(name, root + "models/" + name + ".json");
  const FourBarRoutes& r = fourbar_routes();
  const LoopState fourbar{r.q_loop, r.v_loop, r.tau_loop};
  add_loop_case("finger_fourbar_loop", root + "models/finger_fourbar_loop.json", &fourbar, false);
  add_loop_case("hand_fourbar_loop", root + "models/hand_fourbar_loop.json");
}

MechanismSpec random_spec(int seed, int bodies, double branching) {
  const std::string text = R"({"model": "random_tree", "params": {"seed": )" +
                           std::to_string(seed) + R"(, "bodies": )" + std::to_string(bodies) +
                           R"(, "branching": )" + std::to_string(branching) +
                           R"(}, "gravity": [0.1, -0.2, -9.81]})";
  return parse_spec(text, "random");
}

// Removes "--flag=a,b,…" from argv and returns its integers ("--flag=" gives none), or
// `fallback` when the flag is not given.
std::vector<int> take_sizes(int& argc, char** argv, const std::string& flag,
                            std::vector<int> fallback) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]).rfind(flag, 0) == 0) {
      std::vector<int> sizes;
      std::stringstream list(argv[i] + flag.size());
      for (std::string item; std::getline(list, item, ',');) sizes.push_back(std::stoi(item));
      for (int k = i; k + 1 < argc; ++k) argv[k] = argv[k + 1];
      --argc;
      return sizes;
    }
  return fallback;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string root = std::string(FEMDYN_SOURCE_DIR) + "/";
  // --sizes=a,b,...: the random chains and trees (default 8 to 1024); --sizes= for none.
  std::vector<int> sizes = take_sizes(argc, argv, "--sizes=", {8, 16, 32, 64, 128, 256, 512, 1024});
  // --load-sizes=a,b,...: the generated chains and trees loaded (default 1,000 to 200,000).
  std::vector<int> load_sizes = take_sizes(
      argc, argv, "--load-sizes=", {1000, 2000, 5000, 10000, 20000, 50000, 100000, 200000});
  try {
    const auto file = [&](std::string path) { return [path] { return read_spec(path); }; };
    const auto random = [](int seed, int n, double branching) {
      return [=] { return random_spec(seed, n, branching); };
    };
    for (const char* name : {"pendulum", "spatial_double_pendulum", "branched_tree", "finger",
                             "finger_coupled", "hand"})
      add_case(name, file(root + "models/" + name + ".json"));
    add_case("hand16", file(root + "models/urdf/hand16.urdf"));
    for (const char* name : {"iiwa", "hyq", "atlas"}) {
      const std::string path = root + "tests/robots/" + name + ".urdf";
      add_case(name, file(path), {path});
    }
    for (const char* name : {"hyq", "atlas"}) {  // on a floating base (--floating-base)
      const std::string path = root + "tests/robots/" + name + ".urdf";
      add_case(std::string(name) + "_floating",
               [path] { return read_spec(path, {.floating_base = true}); }, {path, true});
    }
    add_case("random_chain20", random(20, 20, 0));
    // Growth with n: serial chains and branching trees (docs/performance.md).
    for (int n : sizes) add_case("chain" + std::to_string(n), random(3, n, 0));
    for (int n : sizes) add_case("tree" + std::to_string(n), random(3, n, 0.5));
    register_fourbar_routes(root);
    add_loop_cases(root);
    add_case("hand_fourbar", file(root + "models/hand_fourbar.json"));
    for (int n : sizes) add_loop_chain(n);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "femdyn_bench: %s\n", e.what());
    return 1;
  }
  for (const auto& c : cases()) register_case(c.get());
  for (const auto& c : loop_cases()) register_loop_case(c.get());
  for (const bool tree : {false, true})
    for (int n : load_sizes) register_load(tree, n);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  for (const std::string& f : failures()) std::fprintf(stderr, "femdyn_bench: %s\n", f.c_str());
  return failures().empty() ? 0 : 1;
}
