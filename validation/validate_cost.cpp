// The validator's first part: the Simbody twin built from the model, the cost of the comparison
// probed on the model itself, and the refusal of a run beyond its budget or memory
// (docs/validation.md, "Bounded work").
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/spatial/inertia.hpp"
#include "core/workspace/memory.hpp"
#include "validation/validate_loops.hpp"
#include "validation/validator.hpp"

namespace femdyn::validation {
namespace {

// Cost model constants, measured on a 2-core x86-64 machine (docs/validation.md, "Bounded
// work"); everything else is timed on the model itself.
//   femdyn's M^s beyond kEvaluateProbeLimit coordinates (timed directly below it): per path
//   entry S_kᵀ I^c S_i formed, and per entry of the n x n matrix (mirrored), measured on chains
//   and trees of 3000 and 10,000 bodies; the products M^s V (kMassProducts of them), per entry;
constexpr int kEvaluateProbeLimit = 3000;
constexpr double kSecondsPerPathEntry = 4e-9;
constexpr double kSecondsPerMatrixEntry = 1.5e-9;
constexpr double kSecondsPerProductEntry = 2.5e-9;
//   the Transform route's Tᵀ (M T), per multiply-add;
constexpr double kSecondsPerFlop = 1e-9;
//   Simbody's trajectory, timed over 1/kSimbodyProbeParts of it (its tighter run: kTightRatio);
constexpr double kSimbodyProbeParts = 20;
constexpr double kProbeSeconds = 1;  // the least time the probe of Simbody's run is given
//   memory per body of the twin (Simbody's system and state) and of femdyn's workspaces.
constexpr double kBytesPerBody = 20e3;

// s: evaluate() on a model too large to time it (it would form the n x n matrix): 2 inverse
// dynamics (t_id), each pair of columns on a path, and each entry of M^s.
double modelled_evaluate_seconds(const Model& m, double t_id) {
  const int n = m.n();
  double path_entries = 0;
  const double per_entry =
      m.identity_coupling ? 1.0 : std::pow(m.C.nonZeros() / std::max(1.0, double(m.n_theta())), 2);
  for (const Body& b : m.bodies) {
    if (!moves(b.joint)) continue;
    for (int a = &b - m.bodies.data(); a >= 0; a = m.bodies[a].parent)
      if (moves(m.bodies[a].joint)) path_entries += per_entry;
  }
  double t_eval =
      2 * t_id + kSecondsPerPathEntry * path_entries + kSecondsPerMatrixEntry * double(n) * n;
  if (m.mass_route == MassRoute::Transform) t_eval += kSecondsPerFlop * 2.0 * m.n_u() * n * n;
  return t_eval;
}

}  // namespace

Validator::Impl::Impl(const Model& model, ValidationOptions options)
    : m(model), o(std::move(options)), ws(model) {
  r.model = m.name;
  r.n = m.n();
  r.states = o.states;
  estimate.n = m.n();
  estimate.states = o.states;
  estimate.budget = o.budget;
  estimate.memory_limit = memory_limit(o.memory_limit);
  estimate.dense_mass = r.dense_mass = m.n() <= kDenseMassLimit;
  if (build()) probe();
  estimate.setup = seconds_since(start);
}

bool Validator::Impl::build() {
  if (m.explicit_table)
    r.notes.push_back(
        "the model gives its correlation table explicitly; DOFs it leaves out or "
        "joins are approximations of the rigid bodies Simbody simulates");
  for (const std::string& a : m.approximations) r.notes.push_back("approximation: " + a);

  // Each body's elements must sum to a rigid body: nothing else can be built in Simbody.
  try {
    tm = twin_model(m);
  } catch (const ModelError& e) {  // a model Simbody cannot hold: no verdict on femdyn
    r.failure = e.what();
    r.not_comparable = true;
    return false;
  }
  if (tm.closed_loop())
    r.notes.push_back("closed loop: " + std::to_string(tm.laws.size()) + " coupled joint(s), " +
                      std::to_string(tm.rods.size()) +
                      " rod(s); Simbody's equations from its constrained forward dynamics");
  const bool rigid = sums_to_rigid_bodies();
  r.not_comparable = rigid && !r.failure.empty();  // Simbody's limit, not the model's
  if (!r.failure.empty()) return false;
  try {
    twin = std::make_unique<SimbodyTwin>(tm);
  } catch (const std::exception& e) {
    r.failure = std::string("Simbody refused the twin: ") + e.what();
    return false;
  }
  // The trajectory of a mechanism with loop constraints is the constrained one, in both, from
  // a consistent start (consistent_state).
  twin->close_loops(!m.constraints.empty());
  if (!m.constraints.empty())
    r.notes.push_back(
        "loop constraints: " + std::to_string(m.constraints.size()) + " (" +
        std::to_string(m.constraint_rows) +
        " equations); M, h, Q, qdd, tau and the kinematics compare the spanning tree, the "
        "constrained rows and the trajectory the closed mechanism");
  // (A mechanism without mass has no centre of mass: momentum_kinematics refuses it.)
  double mass = 0;
  for (const TwinBody& b : tm.bodies) mass += b.mass;
  for (const TwinRod& rod : tm.rods) mass += rod.mass;
  kinematics = m.n() <= kKinematicsLimit && mass > 0;
  frame_jacobian = m.n() <= kFrameJacobianLimit;
  for (const Frame& f : m.frames) frames.push_back({f.body, f.R_BF, f.p_BF});
  if (!r.dense_mass) {
    std::mt19937 rng(o.seed + 7919);  // apart from the states' sequence
    V.resize(m.n(), kMassProducts);
    for (int c = 0; c < kMassProducts; ++c) V.col(c) = random_uniform(m.n(), 1, rng);
  }
  return true;
}

// A body whose elements sum to no rigid body is a failure of the model (r.failure, false); a
// rotary inertia without mass is one of Simbody's (r.failure too, but true: not comparable).
bool Validator::Impl::sums_to_rigid_bodies() {
  bool rigid = true;
  for (std::size_t b = 0; b < tm.bodies.size(); ++b) {
    const TwinBody& tb = tm.bodies[b];
    const Mat3 I_com = tb.inertia_origin - point_inertia(tb.mass, tb.com);  // parallel axis
    if (tb.mass == 0 && !tb.inertia_origin.isZero(0)) {
      r.failure += (r.failure.empty() ? "" : "; ") +
                   ("body '" + m.bodies[b].name +
                    "' has a rotary inertia but no mass, which a Simbody body cannot have");
      continue;
    }
    if (const auto problem = inertia_problem(I_com, tb.inertia_origin.cwiseAbs().maxCoeff())) {
      rigid = false;
      r.failure +=
          (r.failure.empty() ? "" : "; ") +
          ("body '" + m.bodies[b].name + "': its elements sum to no rigid body (" + *problem + ")");
    }
  }
  return rigid;
}

// The costs, from one state of each kind of work (a state apart from the compared ones).
void Validator::Impl::probe() {
  estimate.per_state = probe_state();
  estimate.pointwise = o.states * estimate.per_state;
  if (o.t_end > 0 && o.states > 0) estimate.trajectory = probe_trajectory();
  estimate.bytes = memory_bytes();
}

double Validator::Impl::probe_state() {
  const int n = m.n();
  std::mt19937 rng(o.seed + 104729);
  const VecX q = random_posture(m, rng), qd = random_rates(m, o.qd_scale, rng),
             tau = random_uniform(n, o.tau_scale, rng), qdd = random_uniform(n, o.qdd_scale, rng);
  t_fd = timed([&] { (void)tree_forward_dynamics(m, ws, q, qd, tau); });
  const double t_id = timed([&] { inverse_dynamics(m, ws, q, qd, qdd); });
  const double t_eval = n <= kEvaluateProbeLimit ? timed([&] { evaluate(m, ws, q, qd, tau); })
                                                 : modelled_evaluate_seconds(m, t_id);
  t_energy =
      m.mass_route == MassRoute::Composite ? timed([&] { (void)energy(m, ws, q, qd); }) : t_eval;
  double t_sim = 0;
  try {
    t_sim = timed([&] { (void)twin->equations(q, qd, tau, r.dense_mass ? nullptr : &V); }) +
            timed([&] { (void)twin->inverse_dynamics(q, qd, qdd); });
  } catch (const std::exception&) {
    // A state Simbody cannot take is reported by the comparison itself; the estimate goes on.
  }
  double t_kinematics = 0;  // both engines' frames and momentum
  if (kinematics) {
    t_kinematics = timed([&] { femdyn_kinematics(q, qd, qdd); });
    try {
      t_kinematics += timed([&] { (void)twin->kinematics(q, qd, tau, frames, frame_jacobian); });
    } catch (const std::exception&) {
      // As above: the comparison reports it.
    }
  }
  double seconds = t_fd + t_eval + t_id + t_sim + t_kinematics;
  if (!r.dense_mass) seconds += kSecondsPerProductEntry * double(n) * n;  // M^s V
  return seconds;
}

// The trajectory as usually refined: femdyn's RK4 at dt, dt/2 and dt/4 (7 S0 steps of 4
// evaluations, S0 = t_end / dt, within max_rk4_steps a run), the energy at each sample, and
// Simbody's two runs, timed on the trajectory's first twentieth from its first state (Simbody's
// error control sets its step by the motion at hand, which that stretch shows) and scaled to
// the whole (its steps at 100x the accuracy: 100^(1/4) = 3.2 times as many).
double Validator::Impl::probe_trajectory() {
  const double s0 = std::max(1.0, std::round(o.t_end / o.rk4_step));
  const double samples = std::max(1, o.samples) + 1;
  const double steps = 3 * s0 + (2 * s0 <= o.max_rk4_steps ? 4 * s0 : 0);
  double seconds = steps * 4 * t_fd + samples * t_energy;
  if (!twin->can_simulate()) return seconds;
  std::mt19937 first(o.seed);  // the first state of run(): the trajectory's start
  VecX q0 = random_posture(m, first), qd0 = random_rates(m, o.qd_scale, first);
  std::string why;
  if (!m.constraints.empty()) (void)consistent_state(m, q0, qd0, why);
  const double stretch = o.t_end / kSimbodyProbeParts;
  const double scale = (1 + kTightRatio) * kSimbodyProbeParts;
  // The probe gets its share of the budget, and at least kProbeSeconds whatever the budget:
  // a small budget would otherwise cut it short and the estimate would be the budget
  // echoed back ("at least 5.1 s" for --budget 5, then 6.0 for 6, …). A probe that runs
  // out of even that is a lower bound, said so.
  TwinRunLimits limits;
  limits.wall_time = std::max(o.budget / scale, kProbeSeconds);
  const TwinRun probe =
      twin->simulate(q0, qd0, {0.0, stretch}, o.simbody_accuracy,
                     SimbodyIntegrator::RungeKuttaMerson, TwinSampling::StepToEach, limits);
  simbody_cost = scale * probe.stats.wall_time;
  estimate.at_least = probe.stats.out_of_time;
  return seconds + simbody_cost;
}

// Memory: femdyn's n x n M^s, what its routes form besides, Simbody's matrices, the
// samples, and a measured amount per body.
double Validator::Impl::memory_bytes() const {
  const int n = m.n();
  const double nt = m.n_theta(), nb = static_cast<double>(m.bodies.size());
  double bytes = dense_bytes(n, n) + kBytesPerBody * nb;
  if (m.mass_route == MassRoute::Transform)
    bytes += 2 * dense_bytes(m.n_u(), n) + 2 * dense_bytes(3 * nb, n);  // T, M T, Jω, Jv
  if (m.dynamics_route == DynamicsRoute::Cholesky && m.mass_pattern.solver == SolverKind::Dense)
    bytes += dense_bytes(n, n);                                                 // its factor
  if (m.coupling_level) bytes += 2 * dense_bytes(nt, nt) + dense_bytes(nt, n);  // the tree's
  if (tm.closed_loop())
    bytes += 5 * dense_bytes(n, n);  // q̈'s response, its inverse, M^s, h's and Q's products
  else if (r.dense_mass || !m.identity_coupling)  // a coupled tree forms M to solve for q̈
    bytes += 2 * dense_bytes(nt, nt) + 3 * dense_bytes(n, n);  // calcM, M_θ, Cᵀ M_θ C, a difference
  else
    bytes += 4 * dense_bytes(n, kMassProducts);
  if (o.t_end > 0) bytes += 8 * dense_bytes(std::max(1, o.samples) + 1, 2 * (nt + n));
  if (kinematics && m.mass_route != MassRoute::Transform)
    bytes += 2 * dense_bytes(3 * nb, n);  // Jω, Jv
  if (frame_jacobian) bytes += 2 * dense_bytes(6 * static_cast<double>(frames.size()), n);
  return bytes;
}

std::string Validator::refusal(const std::string& label) const {
  const WorkEstimate& e = impl_->estimate;
  if (!impl_->r.failure.empty() || e.within()) return {};
  const ValidationOptions& o = impl_->o;
  const bool time = e.seconds() > e.budget, memory = e.bytes > e.memory_limit;
  std::string text = label + ": validating n = " + std::to_string(e.n) +
                     " coordinates would take " + (e.at_least ? "at least " : "about ") +
                     format_duration(e.seconds()) + " (" + std::to_string(e.states) +
                     " states of " + format_duration(e.per_state) +
                     (o.t_end > 0 ? ", the trajectory " + format_duration(e.trajectory) : "") +
                     ") and " + format_bytes(e.bytes) + " of memory, beyond ";
  if (time) text += "the budget of " + format_number(e.budget, "%.4g") + " s";
  if (time && memory) text += " and ";
  if (memory)
    text += "the memory limit of " + format_bytes(e.memory_limit) +
            (o.memory_limit > 0 ? "" : " (half the available memory)");
  text += ": use ";
  // How to proceed: no trajectory, fewer states, a larger budget, a larger memory limit.
  std::vector<std::string> ways;
  if (time) {
    const double P = e.pointwise, T = e.trajectory, B = e.budget, s = e.per_state;
    const auto states = [&](double seconds) {
      return std::to_string(std::max(1, static_cast<int>(seconds / s)));
    };
    if (T > 0 && P <= B)
      ways.push_back("--t-end 0 (t_end=0: no trajectory, about " + format_duration(P) + ")");
    // A shorter trajectory: its cost is about proportional to its length (unknown beyond a
    // lower bound when Simbody's probe ran out of time).
    if (const double t_end = T > 0 ? 0.8 * o.t_end * (B - P) / T : 0;
        P < B && t_end >= 1e-3 && !e.at_least)
      ways.push_back("--t-end " + format_number(t_end, "%.2g") + " (t_end=)");
    if (P + T > B && T + s <= B) ways.push_back("--states " + states(B - T) + " (states=)");
    if (T > 0 && P > B && s <= B) ways.push_back("--t-end 0 --states " + states(B));
    ways.push_back("--budget " + format_number(std::ceil(1.1 * e.seconds()), "%.0f") +
                   (e.at_least ? " or more" : "") + " (budget=)");
  }
  if (memory)
    ways.push_back(max_memory_option(e.bytes) + " (max_memory=, GB) if that much memory is free");
  for (std::size_t i = 0; i < ways.size(); ++i)
    text += (i == 0 ? "" : i + 1 == ways.size() ? ", or " : ", ") + ways[i];
  return text;
}

}  // namespace femdyn::validation
