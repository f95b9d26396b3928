// femdyn check MODEL: the numerical diagnosis of a user's model (sim/stability.hpp) over
// sampled states: conditioning of M^s, the modes of the linearised dynamics (the stiffest one
// and the fastest motion, each labelled by kind), the largest stable step of each explicit
// integrator, suspicious bodies, and advice on accuracy and stability: a recommended
// integrator and step, with the error to expect (docs/stability.md).
#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <complex>
#include <iostream>
#include <limits>
#include <optional>
#include <random>

#include "cli/check_modes.hpp"
#include "cli/commands.hpp"
#include "cli/progress.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/workspace/memory.hpp"
#include "io/output.hpp"
#include "sim/stability.hpp"
#include "sim/step_trial.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kCheckHelp =
    R"(usage: femdyn check MODEL [--states K] [--seed S] [--tol r] [--t-end T] [--budget SECONDS] [--json]
                    [--max-memory GB] [--gravity gx,gy,gz]

Diagnoses the model at K seeded states (default 10: q = 0 at rest, then q within the joint
limits and q̇ in ±1), and one more per enforced joint stop (q = 0 with that joint 1e-3 into its
stop, at rest: a stop's stiffness is felt only there; "stop_states" in --json):
  - cond(M^s) = λ_max/λ_min over the states (q̈ loses about log10 cond digits; a cond that
    overflows double precision is said so), symmetry and positive definiteness;
  - the modes of the linearised dynamics A = ∂(q̇, q̈)/∂(q, q̇) (central differences of
    forward dynamics), each labelled: oscillatory (with a damping ratio only where the model
    has dampers), saddle (an unstable equilibrium), decaying (overdamped), growing; the
    stiffest mode (largest |λ|) with the joint and body it moves most, and the fastest motion
    (the fastest mode but the stiff dissipative ones: dissipative and 100x faster than the
    slowest mode);
  - from A the largest stable step of rk4, euler and dopri, the smallest over the states;
  - the natural modes: the oscillatory modes of A about the static equilibrium (femdyn statics
    with τ = 0, q̇ = 0), lowest first, in rad/s and Hz with the coordinate each moves most (an
    elastic model's frequencies, docs/flexible.md); not listed, with the reason, where there is
    no equilibrium or the model has closed loops ("natural_modes" in --json);
  - bodies with suspicious mass properties, by name: near-zero mass or a mass ratio beyond 1e6
    to a neighbour, a near-zero principal inertia, an inertia that violates the triangle
    inequality; a flat body (a disc or plate, on the inequality's boundary) is a note;
  - a recommended integrator and step with the error to expect: rk4 at the step that resolves
    the fastest motion to a relative error --tol per period (default 1e-3; rule in
    docs/stability.md), at most half its stability limit; bdf only where the stiffest mode is
    dissipative and limits rk4 10x below what the motion needs; an undamped fast mode is named
    (remove, damp or resolve it: bdf does not cure it); then tried on the model's own motion:
    rk4 at that step over 3 periods from the initial state and from a state in motion, against
    dopri at rtol 1e-10, halved until its error per period is within 10 tol (dopri advised
    where no step does within the trial's budget), the measured error stated; with --t-end T
    the trial runs over T instead (the run you intend: the promise is then measured over it,
    not extrapolated from 3 periods).
Work is bounded: the time of the whole check is estimated first (4n evaluations and a dense
eigenproblem of 2n per state); beyond --budget seconds (default 120) it is refused with the
estimate, and beyond the memory limit (--max-memory GB, default half the available memory)
with the memory it needs. A progress line shows on a terminal.
A model with closed loops (docs/loops.md) has each state assembled onto its constraints first
(states where they cannot close are counted and left out), its modes are those of the
constrained equations without Baumgarte's term (a fixed-step run projects onto the loops after
every step, which removes its pair -20 1/s from the stability limits), and
the constraint Jacobian's rank (redundant equations) and its nearness to a dead point
(sigma_min/sigma_max of Phi_q, below 1e-6: near) are reported ("loops" in --json).
The coordinates no actuator drives (a free joint's, a joint's with "actuated": false;
docs/control.md#actuation) are listed ("actuated" in --json: the driven ones).
Exit 0: no fault (notes may be printed); 1: M^s is singular at a sampled state, a body is
flagged, or the check would exceed its budget; 2: a bad command line.
)";

// Φ_q's σ_min/σ_max below which a state is reported near a dead point.
constexpr double kDeadPointRatio = 1e-6;

const IntegratorKind kExplicit[] = {IntegratorKind::Rk4, IntegratorKind::Euler,
                                    IntegratorKind::Dopri};

// The joint and body a coordinate belongs to, for naming a mode: "joint 'j2' (body 'link2')",
// or the coordinate's name where it is not a joint's (a coupled coordinate).
std::string where(const Model& m, int a) {
  if (a < 0) return "?";
  const std::string& name = m.coordinate_names[a];
  for (const Body& b : m.bodies)
    if (b.joint.name == name) return "joint '" + name + "' (body '" + b.name + "')";
  return "coordinate '" + name + "'";
}

// Seconds a state costs: 4n evaluations of forward dynamics (timed here) and the dense
// eigenproblems of A (2n, with vectors, then eigenvalues) and of M^s (n), O(N³) each, scaled
// from one timed on a random matrix of up to 200 (eigenvalues and vectors: about 2.5x).
double seconds_per_state(const Model& m) {
  using Clock = std::chrono::steady_clock;
  const auto since = [](Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  };
  Workspace ws(m);
  const VecX q = neutral_posture(m), z = VecX::Zero(m.n());  // (q has n_q entries: quaternions)
  auto begin = Clock::now();
  constexpr int kProbe = 4;
  for (int i = 0; i < kProbe; ++i) (void)tree_forward_dynamics(m, ws, q, z, z);
  const double eval = since(begin) / kProbe;
  const double n = m.n(), N0 = std::min(2 * n, 200.0);
  std::mt19937 rng(7);
  MatX probe = random_uniform(static_cast<int>(N0 * N0), 1.0, rng).reshaped(N0, N0);
  begin = Clock::now();
  (void)Eigen::EigenSolver<MatX>(probe, true);
  const double per_cube = since(begin) / (N0 * N0 * N0);  // s per N³, with vectors
  return 4 * n * eval + per_cube * (1.4 * std::pow(2 * n, 3) + 0.2 * std::pow(n, 3));
}

// "cond from 12 to 3.4e+05 (q̈ loses up to 5.53 digits of 16)"; from 1e16 on, that no digit is
// left; a condition number that overflows double precision (λ_max / λ_min beyond 1.8e308) is
// said so, never printed as inf.
std::string condition_text(double lo, double hi) {
  const auto cond = [](double c) {
    return std::isfinite(c) ? format_short(c) : std::string("beyond 1.8e308");
  };
  const std::string range = "cond from " + cond(lo) + " to " + cond(hi);
  if (!std::isfinite(hi))
    return range + " (it overflows double precision: M^s is singular to double precision at " +
           "some state and q̈ keeps no correct digit)";
  if (hi >= 1e16)  // 1/ε: beyond it no digit of q̈ is left, however many "digits lost"
    return range + " (q̈ keeps no correct digit: M^s is singular to double precision)";
  return range + " (q̈ loses up to " + format_short(std::log10(hi)) + " digits of 16)";
}

Json finite_or_null(double x) { return std::isfinite(x) ? Json(x) : Json(nullptr); }

struct Diagnosis {
  double cond_lo = std::numeric_limits<double>::infinity(), cond_hi = 0, asym = 0;
  int singular_states = 0;
  std::string singular_message;
  Mode stiffest;  // largest |λ| over the states
  Mode fastest;   // the fastest mode but the stiff dissipative ones (the motion to resolve)
  double h_max[3] = {INFINITY, INFINITY, INFINITY};
  // Closed loops: each state assembled onto the constraints first (the states where Newton
  // could not close them are counted and left out), the rank of Φ_q, and the smallest ratio
  // σ_min/σ_max of its non-redundant singular values: how near a state came to a dead point.
  int unassembled = 0, rank = -1, redundant = 0, dead_state = -1;
  double dead_ratio = INFINITY;
  std::string unassembled_message;
};

// Moves (q, q̇) onto the loops and records Φ_q's rank and nearness to a dead point. False when
// the loops cannot close from q.
bool diagnose_loops(const Model& m, int state, VecX& q, VecX& qd, Diagnosis& d) {
  const StateAssembly s = assemble_state(m, q, qd);
  if (!s.assembly.status.ok) {
    ++d.unassembled;
    if (d.unassembled_message.empty()) d.unassembled_message = s.assembly.status.message;
    return false;
  }
  const int rank = s.assembly.rank;
  d.rank = std::max(d.rank, rank);
  d.redundant = m.constraint_rows - d.rank;
  if (const double ratio = dead_point_ratio(m, q, rank); ratio < d.dead_ratio)
    d.dead_ratio = ratio, d.dead_state = state;
  return true;
}

void diagnose_state(const Model& m, Workspace& ws, const VecX& q, const VecX& qd, bool dampers,
                    Diagnosis& d) {
  const VecX tau = VecX::Zero(m.n());
  evaluate(m, ws, q, qd, tau);
  const MassMatrixHealth h = mass_matrix_health(ws.Ms);
  d.asym = std::max(d.asym, h.asymmetry);
  if (h.positive_definite) {  // (a singular state is counted apart, not as cond = inf)
    d.cond_lo = std::min(d.cond_lo, h.condition);
    d.cond_hi = std::max(d.cond_hi, h.condition);
  }
  if (!h.positive_definite) {
    ++d.singular_states;
    const Status st = ws.solver.factorize(ws.Ms);
    if (d.singular_message.empty()) d.singular_message = st.ok ? "λ_min ≤ 0" : st.message;
    return;
  }
  // Closed loops at Baumgarte rate 0: a fixed-step run projects onto the loops after every step,
  // so Baumgarte's pair −ω does not limit its step (docs/stability.md, the loops class).
  const Linearization lin = linearize(m, ws, q, qd, tau, 0);
  if (!lin.status.ok) return;
  // Stiff and dissipative: a dissipative mode more than 100x faster than the slowest mode,
  // which decays long before the motion around it has moved. The fastest of the others is the
  // motion a step must resolve.
  const std::vector<Mode> md = modes(lin, dampers);
  double slowest = std::numeric_limits<double>::infinity();
  for (const Mode& x : md)
    if (x.kind != ModeKind::None) slowest = std::min(slowest, x.omega);
  for (const Mode& x : md) {
    if (x.omega > d.stiffest.omega) d.stiffest = x;
    const bool stiff_dissipative = x.dissipative() && x.omega > 100 * slowest;
    if (!stiff_dissipative && x.kind != ModeKind::None && x.omega > d.fastest.omega) d.fastest = x;
  }
  for (int i = 0; i < 3; ++i)
    if (const auto hs = largest_stable_step(lin, kExplicit[i]))
      d.h_max[i] = std::min(d.h_max[i], *hs);
}

// A joint's stop is felt only beyond its limit: one more state per enforced stop, the neutral
// posture with that joint 1e-3 (relative) into its upper stop (else its lower), at rest. Its
// linearisation then holds the stop's mode, of frequency sqrt(k_s / m_eff). Returns how many.
int diagnose_stops(const Model& m, Workspace& ws, bool dampers, Diagnosis& d) {
  int pressed = 0;
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (!J.stop) continue;
    const bool upper = std::isfinite(J.upper);
    const double edge = upper ? J.upper : J.lower;
    VecX q = neutral_posture(m);
    q[c.q] = edge + (upper ? 1 : -1) * 1e-3 * std::max(1.0, std::abs(edge));
    diagnose_state(m, ws, q, VecX::Zero(m.n()), dampers, d);
    ++pressed;
  }
  return pressed;
}

// The advice, as text and as numbers (dt 0 where no step is recommended).
struct Advice {
  std::string text, integrator;
  double dt_rk4 = 0, dt_euler = 0, error_per_period = 0, period = 0;
  bool stability_limited = false;
  std::optional<StepTrial> trial;  // the rk4 step tried on the model's own motion
};

Advice advise(const Model& m, const Diagnosis& d, double tol) {
  Advice a;
  if (d.singular_states > 0) {
    a.text = "none: M^s is singular at " + std::to_string(d.singular_states) +
             " of the states; repair the model first";
    return a;
  }
  const double limit = d.h_max[0];
  if (d.fastest.omega == 0 && !std::isfinite(limit)) {
    a.integrator = "dopri";
    a.text = "dopri --rtol " + format_short(tol) + ": no mode was found (nothing moves by itself)";
    return a;
  }
  // The step that resolves the fastest motion, and at most half the stability limit.
  const double resolve = resolving_step(IntegratorKind::Rk4, d.fastest.omega, tol);
  a.dt_rk4 = std::min(resolve, 0.5 * limit);
  a.stability_limited = 0.5 * limit < resolve;
  a.dt_euler =
      std::min(resolving_step(IntegratorKind::Euler, d.fastest.omega, tol), 0.5 * d.h_max[1]);
  a.period = d.fastest.omega > 0 ? 2 * std::numbers::pi / d.fastest.omega : 0;
  a.error_per_period =
      d.fastest.omega > 0 ? error_per_period(IntegratorKind::Rk4, d.fastest.omega, a.dt_rk4) : 0;

  const std::string stiff = d.stiffest.text() + ", in " + where(m, d.stiffest.coordinate);
  // Stiffness BDF cures: a dissipative stiffest mode that limits rk4 10x below what the motion
  // needs (it decays, so nothing is lost by stepping over it implicitly).
  if (d.stiffest.dissipative() && 0.5 * limit * 10 < resolve) {
    a.integrator = "bdf";
    a.text = "bdf --rtol " + format_short(tol) + ": the stiffest mode (" + stiff +
             ") is dissipative and limits rk4 to dt < " + format_short(limit) + " s, " +
             format_short(resolve / limit) + "x below the " + format_short(resolve) +
             " s that the motion needs";
    return a;
  }
  a.integrator = "rk4";
  std::string text = "rk4 --dt " + format_short(a.dt_rk4) + " (";
  if (a.stability_limited)
    text += "half its stability limit " + format_short(limit) + " s";
  else
    text += format_short(a.period / a.dt_rk4) + " steps a period of the fastest motion, " +
            d.fastest.text() + ", period " + format_short(a.period) + " s";
  text += "): expect a relative error of about " + format_short(a.error_per_period) +
          " per period (" + format_short(a.error_per_period) + " x t / " + format_short(a.period) +
          " s over a run of t); or dopri --rtol " + format_short(tol);
  if (!d.stiffest.dissipative() && d.stiffest.kind == ModeKind::Oscillatory && limit < 1e-4)
    text += ". The stiffest mode (" + stiff + ", limit " + format_short(limit) +
            " s) is an undamped fast oscillation: remove it (merge a tiny body into its "
            "neighbour, or fix the joint), damp it, or resolve it; bdf does not cure it (it "
            "must still follow or damp the oscillation)";
  a.text = text;
  return a;
}

// The advice tried on the model's own motion (sim/step_trial.hpp), over 3 periods of the fastest
// motion from two starts: the initial state (the neutral posture at rest, what `simulate` starts
// from; often an equilibrium that does not move) and a seeded state in motion (q within the
// limits, q̇ in ±1). rk4's step is halved until its error per period is within 10 tol from both;
// where no step does within the trial's budget, dopri is advised instead. The advice then states
// what was measured.
// With --t-end the trial runs over the user's whole run instead (its step budget grown to
// 4 T / dt, at most 5e7 / n steps).
void verify_advice(const Model& m, double tol, unsigned seed, double t_end, Advice& a) {
  if (a.integrator != "rk4" || !(a.dt_rk4 > 0) || !(a.period > 0)) return;
  const double n = std::max(1, m.n());
  StepTrialOptions o{.period = a.period,
                     .allowed = 10 * tol,
                     .step_budget = std::max(2000L, static_cast<long>(1e6 / n))};
  if (t_end > 0) {
    o.horizon = t_end;
    o.step_budget = std::max(o.step_budget,
                             static_cast<long>(std::min(5e7 / n, 4 * std::ceil(t_end / a.dt_rk4))));
  }
  std::mt19937 rng(seed);
  const VecX q1 = random_posture(m, rng), qd1 = random_uniform(m.n(), 1, rng);
  StepTrial t =
      try_fixed_step(m, IntegratorKind::Rk4, a.dt_rk4, neutral_posture(m), VecX::Zero(m.n()), o);
  std::string starts = "from its initial state and from a state in motion";
  if (t.verified) {
    const StepTrial moving = try_fixed_step(m, IntegratorKind::Rk4, t.dt, q1, qd1, o);
    if (moving.reference_failed) {  // that start's own motion cannot be followed: the first holds
      starts = "from its initial state (the state in motion met: " + moving.failure + ")";
    } else {  // the error the advice states: the larger of the two starts' at the final step
      const int before = t.halvings;
      StepTrial first = t;
      if (moving.verified && moving.halvings > 0)
        first = try_fixed_step(m, IntegratorKind::Rk4, moving.dt, neutral_posture(m),
                               VecX::Zero(m.n()), o);
      t = moving;
      t.halvings += before;
      if (t.verified && first.verified) {
        t.error = std::max(t.error, first.error);
        t.error_per_period = std::max(t.error_per_period, first.error_per_period);
      }
    }
  }
  a.trial = t;
  const std::string over = format_short(t.horizon) + " s of the model's motion " + starts +
                           " (against dopri at rtol 1e-10)";
  if (!t.verified) {
    a.integrator = "dopri";
    a.text = "dopri --rtol " + format_short(tol) + ": rk4 at the linear rule's " +
             format_short(a.dt_rk4) + " s does not hold on the model's own motion: " + t.failure;
    a.dt_rk4 = 0;
    return;
  }
  const std::string measured =
      t_end > 0 ? "measured " + format_short(t.error) + " over the whole run of " + over + " (" +
                      format_short(t.error_per_period) + " per period)"
                : "measured " + format_short(t.error_per_period) + " per period over " + over +
                      "; the promise holds over that horizon: a longer run can err more than the "
                      "rate says (--t-end T measures over yours)";
  if (t.halvings == 0) {
    a.text += "; " + measured;
    return;
  }
  a.text =
      "rk4 --dt " + format_short(t.dt) + " (the linear rule's " + format_short(a.dt_rk4) +
      " s halved " + std::to_string(t.halvings) +
      " times: the model's motion is faster or stiffer than at the sampled states): " + measured +
      "; or dopri --rtol " + format_short(tol);
  a.dt_rk4 = t.dt;
  a.error_per_period = t.error_per_period;
}

Json mode_json(const Model& m, const Mode& md) {
  return {{"lambda", {md.lambda.real(), md.lambda.imag()}},
          {"omega", md.omega},
          {"kind", md.text()},
          {"damping_ratio", std::isnan(md.zeta) ? Json(nullptr) : Json(md.zeta)},
          {"where", where(m, md.coordinate)}};
}

// What check found: the diagnosis over the states, the states pressed into stops, the bodies
// worth a look, and the advice verified.
struct CheckReport {
  int states = 0, pressed = 0;
  Diagnosis d;
  std::vector<SuspiciousBody> bodies;
  Advice advice;
  double tol = 0;
  NaturalModes natural;  // about the static equilibrium (cli/check_modes.hpp)
};

// Checking K states costs about per_state each: beyond the budget, refused naming the way on.
bool within_budget(const Args& a, const Model& m, int K, double budget) {
  const int n = m.n();
  const double per_state = seconds_per_state(m);
  if (per_state * K <= budget) return true;
  const int fit = static_cast<int>(budget / per_state);
  std::cerr << "femdyn check: " << escaped(a.positional[0]) << ": checking " << K << " states of "
            << n << " coordinates would take about " << format_duration(per_state * K) << " ("
            << format_duration(per_state)
            << " a state: 4n evaluations and dense eigenproblems of 2n = " << 2 * n
            << "), beyond the budget of " << format_duration(budget) << ": "
            << (fit >= 1 ? "use --states " + std::to_string(fit) + " or raise --budget"
                         : "even one state exceeds it; raise --budget to at least " +
                               format_number(std::ceil(per_state), "%.0f") +
                               " (seconds) with --states 1")
            << "\n";
  return false;
}

// The diagnosis at K states: the neutral posture at rest, then seeded random ones (each
// assembled onto the loops first, where there are loops).
Diagnosis diagnose(const Model& m, Workspace& ws, int K, std::mt19937& rng,
                   const std::string& label) {
  const int n = m.n();
  Diagnosis d;
  const bool dampers = has_dampers(m);
  Progress progress(K, "states");
  for (int k = 0; k < K; ++k) {
    VecX q = k == 0 ? neutral_posture(m) : random_posture(m, rng);
    VecX qd = k == 0 ? VecX::Zero(n) : random_rates(m, 1.0, rng);
    if (m.constraints.empty() || diagnose_loops(m, k, q, qd, d))
      diagnose_state(m, ws, q, qd, dampers, d);
    progress.update(k + 1);
  }
  // Loops that close at none of the states tried leave nothing to diagnose: refused as simulate
  // refuses them (exit 1), never a report of empty ranges.
  if (!m.constraints.empty() && d.unassembled == K)
    throw StateError(label + ": the loops close at none of the " + std::to_string(K) +
                     " states tried: " + d.unassembled_message);
  return d;
}

Json check_json(const Model& m, const CheckReport& r) {
  const int n = m.n();
  Json j = {
      {"model", m.name},
      {"n", n},
      {"coordinates", m.coordinate_names},
      {"actuated", actuated_names(m)},
      {"states", r.states},
      {"stop_states", r.pressed},
      {"condition", {{"min", finite_or_null(r.d.cond_lo)}, {"max", finite_or_null(r.d.cond_hi)}}},
      {"condition_overflows", r.d.singular_states < r.states && !std::isfinite(r.d.cond_hi)},
      {"digits_lost", finite_or_null(std::log10(r.d.cond_hi))},
      {"asymmetry", r.d.asym},
      {"singular_states", r.d.singular_states},
      {"stiffest_mode", mode_json(m, r.d.stiffest)},
      {"fastest_motion", mode_json(m, r.d.fastest)},
      {"recommendation", r.advice.text},
      {"recommended",
       {{"integrator", r.advice.integrator},
        {"tol", r.tol},
        {"rk4_dt", r.advice.dt_rk4},
        {"euler_dt", r.advice.dt_euler},
        {"rk4_error_per_period", r.advice.error_per_period},
        {"period", r.advice.period},
        {"stability_limited", r.advice.stability_limited}}}};
  if (r.advice.trial)
    j["recommended"]["trial"] = {
        {"verified", r.advice.trial->verified},
        {"rk4_dt", r.advice.trial->dt},
        {"halvings", r.advice.trial->halvings},
        {"horizon", r.advice.trial->horizon},
        {"error_per_period", finite_or_null(r.advice.trial->error_per_period)},
        {"error", finite_or_null(r.advice.trial->error)},
        {"failure", r.advice.trial->failure}};
  Json steps = Json::object();
  for (int i = 0; i < 3; ++i)
    steps[integrator_name(kExplicit[i])] =
        std::isfinite(r.d.h_max[i]) ? Json(r.d.h_max[i]) : Json(nullptr);
  j["largest_stable_step"] = steps;
  Json flags = Json::array(), notes = Json::array();
  for (const auto& b : r.bodies)
    (b.note ? notes : flags).push_back({{"body", b.name}, {"why", b.why}});
  j["suspicious_bodies"] = flags;
  j["notes"] = notes;
  if (!r.d.singular_message.empty()) j["singular"] = r.d.singular_message;
  if (!m.constraints.empty())
    j["loops"] = {{"equations", m.constraint_rows},
                  {"rank", r.d.rank},
                  {"redundant", r.d.redundant},
                  {"unassembled_states", r.d.unassembled},
                  {"dead_point_ratio", finite_or_null(r.d.dead_ratio)},
                  {"near_dead_point", r.d.dead_ratio < kDeadPointRatio}};
  j["natural_modes"] = natural_modes_json(m, r.natural);
  return j;
}

void print_check(const Model& m, const CheckReport& r) {
  const int n = m.n();
  std::cout << "model: " << m.name << " (" << n << " coordinates, " << m.bodies.size()
            << " bodies), " << r.states << " states"
            << (r.pressed ? " and " + std::to_string(r.pressed) + " pressed into their joint stops"
                          : std::string())
            << "\n";
  if (!m.fully_actuated()) {  // (docs/control.md#actuation)
    std::cout << "actuation: " << m.n_actuated() << " of " << n << " coordinates driven; not:";
    for (int i = 0, k = 0; i < n; ++i)
      if (k < m.n_actuated() && m.actuated[k] == i)
        ++k;
      else
        std::cout << " " << m.coordinate_names[i];
    std::cout << "\n";
  }
  if (r.d.singular_states)
    std::cout << "M^s: singular at " << r.d.singular_states << " of " << r.states
              << " states: " << r.d.singular_message << "\n";
  if (r.d.singular_states < r.states)
    std::cout << "M^s: " << condition_text(r.d.cond_lo, r.d.cond_hi) << ", symmetric to "
              << format_short(r.d.asym)
              << (r.d.singular_states ? "" : ", positive definite at every state") << "\n";
  if (!m.constraints.empty()) {
    std::cout << "loops: " << m.constraint_rows << " constraint equations, rank " << r.d.rank
              << " (" << r.d.redundant << " redundant) at the states assembled onto them";
    if (r.d.unassembled)
      std::cout << "; " << r.d.unassembled << " of " << r.states
                << " states could not be assembled (left out): " << r.d.unassembled_message;
    if (std::isfinite(r.d.dead_ratio))
      std::cout << "\nnearest dead point: sigma_min/sigma_max of Phi_q = "
                << format_short(r.d.dead_ratio) << " at state " << r.d.dead_state
                << (r.d.dead_ratio < kDeadPointRatio
                        ? " (near a dead point: the constraint forces there are large, and at "
                          "the point itself the motion fails)"
                        : "");
    std::cout << "\n";
  }
  std::cout << "stiffest mode: |λ| = " << format_short(r.d.stiffest.omega) << " 1/s, "
            << r.d.stiffest.text() << ", in " << where(m, r.d.stiffest.coordinate) << "\n"
            << "fastest motion: " << r.d.fastest.text() << ", in "
            << where(m, r.d.fastest.coordinate) << "\nlargest stable step:";
  for (int i = 0; i < 3; ++i)
    std::cout << " " << integrator_name(kExplicit[i]) << " "
              << (std::isfinite(r.d.h_max[i]) ? format_short(r.d.h_max[i]) + " s"
                                              : std::string("unlimited"))
              << (i < 2 ? "," : "");
  // BDF1–2 are A-stable; BDF3–5 are not, and undamped modes at many frequencies hold them near
  // 1/ω_max (docs/simulation.md, "BDF's order").
  const bool undamped = r.d.stiffest.kind == ModeKind::Oscillatory && !r.d.stiffest.dissipative();
  std::cout << (undamped ? " (bdf: unlimited at --max-order 2; at orders 3-5 undamped modes can "
                           "hold it near 1/omega)\n"
                         : " (bdf: unlimited)\n")
            << natural_modes_text(m, r.natural) << "\n";
  if (r.bodies.empty()) std::cout << "suspicious bodies: none\n";
  for (const auto& b : r.bodies)
    std::cout << (b.note ? "note: body '" : "suspicious body '") << b.name << "': " << b.why
              << "\n";
  std::cout << "recommended: " << r.advice.text << "\n";
}

}  // namespace

int cmd_check(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"},
                            {"states", "seed", "tol", "budget", "gravity", "max-memory", "t-end"});
  if (a.has("help")) {
    std::cout << kCheckHelp;
    return 0;
  }
  const Model m = load(a);
  CheckReport r;
  r.states = static_cast<int>(integer_option(a, "states", 10, 1, 10000));
  const unsigned seed = static_cast<unsigned>(integer_option(a, "seed", 1, 0, 4294967295.0));
  r.tol = number_option(a, "tol", 1e-3);
  if (!(r.tol > 0 && r.tol < 1)) throw CliError("--tol expects a relative error in (0, 1)");
  const double budget = number_option(a, "budget", 120);
  if (!(budget > 0)) throw CliError("--budget expects a positive number of seconds");
  double t_end = 0;
  if (a.has("t-end")) {
    t_end = number_option(a, "t-end", 0);
    if (!(t_end > 0) || t_end > 1e6) throw CliError("--t-end expects a time in (0, 1e6] s");
  }

  // Bounded work: estimated up front, refused beyond the memory limit and the budget. Memory:
  // the workspace's M^s, the 2n x 2n linearisation A and its eigenproblem (the real Schur form,
  // its vectors and the complex eigenvectors, about 6 matrices of 2n).
  const int n = m.n();
  const double bytes = evaluation_bytes(m) + 6 * dense_bytes(2 * n, 2 * n);
  require_memory(a.positional[0] + ": checking n = " + std::to_string(n) + " coordinates", bytes,
                 max_memory(a), "use " + max_memory_option(bytes) + " if that much memory is free");
  if (!within_budget(a, m, r.states, budget)) return 1;

  std::mt19937 rng(seed);
  Workspace ws(m);
  r.d = diagnose(m, ws, r.states, rng, a.positional[0]);
  r.pressed = diagnose_stops(m, ws, has_dampers(m), r.d);
  r.bodies = suspicious_bodies(m);
  bool flagged = false;
  for (const auto& b : r.bodies) flagged = flagged || !b.note;
  r.advice = advise(m, r.d, r.tol);
  r.natural = natural_modes(a, m);
  verify_advice(m, r.tol, seed, t_end, r.advice);
  if (a.has("json"))
    std::cout << json_text(check_json(m, r)) << "\n";
  else
    print_check(m, r);
  return r.d.singular_states > 0 || flagged ? 1 : 0;
}

}  // namespace femdyn::cli
