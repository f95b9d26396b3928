// femdyn track: computed-torque feed-forward along a smooth point-to-point motion, replayed
// open loop in forward simulation, or with PD feedback closed through the control loop
// (sim/control_loop.hpp) — the control use of the equations.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>

#include "cli/commands.hpp"
#include "cli/interrupt.hpp"
#include "compile/actuators.hpp"
#include "io/atomic_file.hpp"
#include "io/csv.hpp"
#include "io/output.hpp"
#include "models/model_files.hpp"
#include "sim/control_loop.hpp"
#include "sim/fixed_step.hpp"
#include "sim/quintic.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kTrackHelp =
    R"(usage: femdyn track MODEL --to a,b,… [--from …] [--duration T] [--steps N] [--csv FILE [--force]] [--json]
                     [--actuated-base]
                     [--kp KP --kd KD [--start q] [--control evaluation|hold]] [--gravity gx,gy,gz]

Plans the quintic (minimum-jerk) motion q_ref(t) from --from (default 0, the identity rotation
for a ball or free joint) to --to in T seconds (default 1), along each joint's geodesic
(q_ref = q_from ⊕ s(t/T)(q_to ⊖ q_from); n_q values each, quaternions (w, x, y, z)), computes the joint torques τ(t) = M^s q̈_ref + h − Q(τ = 0) by inverse dynamics,
then simulates the model under τ(t) alone (RK4, N steps, default 1000) and reports how closely
the simulated motion follows q_ref (max |q_sim ⊖ q_ref|: rad or m; a rotation by the rotation
vector between the two quaternions). --csv writes t, q_ref, τ and q_sim per step (streamed to a
temporary file renamed into place at the end, so that it appears whole or not at all, its size
checked against the disk first; an existing FILE is replaced only with --force, and never when it
is MODEL). Ctrl-C stops the run: exit 130, FILE not written. --json prints
{"model", "n", "coordinates", "duration", "steps", "max_tracking_error", "max_abs_tau",
"final_tracking_error", "feedback"}. τ acts on every coordinate, so a model with closed loops is
refused (exit 1), and so is one with a coordinate no actuator drives (docs/control.md#actuation:
a free joint, a floating base, unless --actuated-base says that its base is pushed too, by
thrusters whose wrench is the τ on its 6 rates; a joint with "actuated": false).

With --kp and --kd (1/s², 1/s; e.g. ω² and 2ω) the loop is closed: computed torque with PD,
  τ = M^s(q) (q̈_ref + K_d (v_ref − v) + K_p (q_ref ⊖ q)) + h(q, v) − Q(q, v, τ = 0),
so that the error obeys ë + K_d ė + K_p e = 0; sampled at every step and held (--control hold,
the default: a digital controller at 1/dt) or called at every evaluation (--control evaluation)
(docs/control.md). --start q0 starts the model off the reference (default: --from), to see the
error converge.
)";

// Computed torque with PD about the reference at t (held or per evaluation: ControlLoop).
struct ComputedTorque {
  const Model& m;
  const VecX &q_from, &delta;
  double T, kp, kd;
  Workspace ws{m}, wref{m};
  VecX qr, vr, ar;
  void operator()(double t, const VecX& q, const VecX& v, VecX& tau) {
    quintic(m, q_from, delta, T, std::min(t, T), qr, vr, ar);
    evaluate(m, ws, q, v, VecX::Zero(m.n()));  // M^s, h, Q(τ = 0)
    const VecX a = ar + kd * (vr - v) + kp * configuration_difference(m, q, qr);
    tau = ws.Ms * a + ws.h - ws.Q;
  }
};

// A failed run's message; a diverged one under feedback adds whether the PD gains made the
// loop at the start grow (sim/controller_diagnosis.hpp: the gain K of the law by differences, the
// closed loop held over each step or inside f), so the report names them as the suspect.
std::string failure_text(const Status& st, const ControlLoop& loop, ComputedTorque& law,
                         const VecX& q_start, bool feedback, ControlMode mode) {
  if (!feedback || !st.diverged) return st.message;
  const Control u = [&law](double t, const VecX& q, const VecX& v, VecX& out) {
    law(t, q, v, out);
  };
  const std::string why = loop.controller_clause(u, 0, q_start, VecX::Zero(law.m.n()),
                                                 mode == ControlMode::ZeroOrderHold);
  return why.empty() ? st.message
                     : st.message + "; " + why + " (--kp " + format_number(law.kp) + ", --kd " +
                           format_number(law.kd) + ")";
}

// Computed torque puts a τ on every coordinate. A model where that is not the mechanism's own
// actuation is refused, naming what would be ignored: closed loops (the open tree's τ would be
// applied, and the loops' forces left out) and a coordinate no actuator drives (Model::actuated:
// a floating base nothing pushes, a passive joint).
void require_fully_actuated(const std::string& file, const Model& m) {
  if (!m.prescribed.empty())
    throw ModelError(file, "joint '" + m.prescribed[0].joint +
                               "' is prescribed in time (a driven joint): computed torque would "
                               "fight its drive (not supported)");
  if (!m.constraints.empty())
    throw ModelError(file, "the model has closed loops (" + std::to_string(m.constraint_rows) +
                               " constraint equations); computed torque by the spanning tree's "
                               "inverse dynamics would ignore them (not supported)");
  for (const Body& b : m.bodies) {
    if (b.joint.actuated) continue;
    if (b.joint.type == JointType::Free)
      throw ModelError(file, "body '" + b.name + "' is on a free joint ('" + b.joint.name +
                                 "'): computed torque would push on a base nothing actuates "
                                 "(free-floating tracking is not supported; --actuated-base if "
                                 "thrusters push it)");
    throw ModelError(file, "joint '" + b.joint.name +
                               "' is not actuated (\"actuated\": false): "
                               "computed torque would push on it (underactuated tracking is not "
                               "supported)");
  }
}

// --csv: rows streamed to a file that appears whole or not at all (io/atomic_file.hpp), its size
// checked against the disk first: (N + 1) rows of 2 n_q + n + 1 numbers, at most 24 bytes each.
class TrackCsv {
 public:
  TrackCsv(const std::string& path, bool force, const Model& m, int steps) : out_(path, force) {
    const double bytes = (steps + 1.0) * (2.0 * m.n_q() + m.n() + 1) * 24;
    if (const double free = out_.shortfall(bytes); free > 0)
      throw CliError("--csv " + path + ": the table would take up to " + format_short(bytes / 1e9) +
                     " GB and the disk has " + format_short(free / 1e9) +
                     " GB free: fewer --steps");
    std::ostream& o = out_.stream();
    o.precision(12);
    o << "t";  // names quoted where they need it (RFC 4180): a coordinate "a,b" stays one column
    for (const auto& c : m.configuration_names) o << ',' << csv_field("q_ref_" + c);
    for (const auto& c : m.coordinate_names) o << ',' << csv_field("tau_" + c);
    for (const auto& c : m.configuration_names) o << ',' << csv_field("q_sim_" + c);
    o << "\n";
  }
  void row(double t, const VecX& q_ref, const VecX& tau, const VecX& q_sim) {
    std::ostream& o = out_.stream();
    o << t;
    for (const VecX* v : {&q_ref, &tau, &q_sim})
      for (Eigen::Index i = 0; i < v->size(); ++i) o << ',' << (*v)[i];
    o << "\n";
  }
  void commit() {
    try {
      out_.commit();
    } catch (const std::runtime_error& e) {
      throw CliError(std::string("--csv ") + e.what());
    }
  }
  const std::string& path() const { return out_.path(); }

 private:
  AtomicFile out_;
};

// The --csv file, opened before any work (a file it may not replace is refused then).
std::optional<TrackCsv> open_csv(const Args& a, const Model& m, int steps) {
  if (!a.has("csv")) return std::nullopt;
  try {
    return std::make_optional<TrackCsv>(a.options.at("csv"), a.has("force"), m, steps);
  } catch (const std::runtime_error& e) {
    throw CliError(std::string("--csv ") + e.what());
  }
}

// --csv: refused before any work if it would clobber an input or, without --force, a file.
void refuse_csv_target(const Args& a) {
  if (!a.has("csv")) return;
  const std::string& out = a.options.at("csv");
  std::error_code ec;
  if (const std::string input = input_at(out, model_inputs(a.positional[0])); !input.empty())
    throw CliError("--csv " + out + " is " + input);
  if (std::filesystem::exists(out, ec) && !a.has("force"))
    throw CliError("--csv " + out + ": exists (use --force to replace it)");
}

// --kp, --kd and --control: the PD feedback, if any (--start needs it too).
struct Feedback {
  bool on = false;
  double kp = 0, kd = 0;
  ControlMode mode = ControlMode::ZeroOrderHold;
};
Feedback feedback_options(const Args& a) {
  Feedback f;
  f.on = a.has("kp") || a.has("kd");
  if (f.on && !(a.has("kp") && a.has("kd"))) throw CliError("--kp and --kd go together");
  f.kp = f.on ? number_option(a, "kp", 0) : 0;
  f.kd = f.on ? number_option(a, "kd", 0) : 0;
  if (!(f.kp >= 0) || !(f.kd >= 0)) throw CliError("--kp and --kd expect numbers ≥ 0");
  if (a.has("control")) {
    const std::string& c = a.options.at("control");
    if (c == "evaluation")
      f.mode = ControlMode::PerEvaluation;
    else if (c != "hold")
      throw CliError("--control expects evaluation or hold");
    if (!f.on) throw CliError("--control needs --kp and --kd");
  }
  if (a.has("start") && !f.on) throw CliError("--start needs --kp and --kd");
  return f;
}

struct TrackResult {
  double max_err = 0, max_tau = 0, final_err = 0;
};

void print_track(const Args& a, const Model& m, double T, int N, const Feedback& f,
                 const TrackResult& r) {
  if (a.has("json")) {
    const char* control = f.mode == ControlMode::PerEvaluation ? "evaluation" : "hold";
    std::cout << json_text(
                     Json{{"model", m.name},
                          {"n", m.n()},
                          {"coordinates", m.coordinate_names},
                          {"duration", T},
                          {"steps", N},
                          {"max_tracking_error", r.max_err},
                          {"final_tracking_error", r.final_err},
                          {"max_abs_tau", r.max_tau},
                          {"feedback", f.on ? Json{{"kp", f.kp}, {"kd", f.kd}, {"control", control}}
                                            : Json(nullptr)}})
              << "\n";
    return;
  }
  std::cout << "model: " << m.name << "\nquintic motion over " << T << " s, " << N << " RK4 steps, "
            << (f.on ? "computed torque with PD feedback (kp " + format_number(f.kp) + ", kd " +
                           format_number(f.kd) + ")\n"
                     : std::string("feed-forward torques by inverse dynamics\n"))
            << "max |tau|: " << r.max_tau << "\nmax |q_sim - q_ref|: " << r.max_err
            << "\nfinal |q_sim - q_ref|: " << r.final_err << "\n";
}

}  // namespace

int cmd_track(int argc, char** argv) {
  const Args a = parse_args(
      argc, argv, 2, {"help", "json", "force", "actuated-base"},
      {"to", "from", "duration", "steps", "csv", "gravity", "kp", "kd", "start", "control"});
  if (a.has("help")) {
    std::cout << kTrackHelp;
    return 0;
  }
  if (a.positional.size() != 1) throw CliError("expected one MODEL file (try --help)");
  refuse_csv_target(a);
  Model m = load(a);
  if (a.has("actuated-base")) actuate_free_joints(m);
  require_fully_actuated(a.positional[0], m);
  if (!a.has("to")) throw CliError("--to is required (try --help)");
  const VecX q1 = configuration_vector(a, "to", m);
  const VecX q0 = configuration_vector(a, "from", m);      // (the neutral configuration)
  const VecX delta = configuration_difference(m, q0, q1);  // q1 ⊖ q0, joint by joint
  const double T = number_option(a, "duration", 1.0);
  if (!(T > 0)) throw CliError("--duration expects one positive number");
  const int N = static_cast<int>(integer_option(a, "steps", 1000, 1, 1e7));
  const int n = m.n();
  Workspace wref(m);
  VecX qr(m.n_q()), qdr(n), qddr(n);
  // τ(t) by inverse dynamics of the reference.
  const Actuation tau = [&](double t, VecX& out) {
    quintic(m, q0, delta, T, t, qr, qdr, qddr);
    inverse_dynamics(m, wref, qr, qdr, qddr);
    out = wref.tau;
  };
  VecX u(n);
  const double dt = T / N;
  const Feedback fb = feedback_options(a);
  const bool feedback = fb.on;
  const double kp = fb.kp, kd = fb.kd;
  const ControlMode mode = fb.mode;
  const VecX q_start = a.has("start") ? configuration_vector(a, "start", m) : q0;
  // Open loop: τ(t) alone, by RK4. Closed: the same RK4 step under computed torque with PD.
  Rk4 rk4(m, {.dt = dt}, tau);
  ComputedTorque law{m, q0, delta, T, kp, kd};
  ControlLoop loop(
      m, {.kind = IntegratorKind::Rk4, .fixed = {.dt = dt}}, {.mode = mode, .period = dt},
      [&law](double t, const VecX& q, const VecX& v, VecX& out) { law(t, q, v, out); });
  Integrator& integ = feedback ? loop.integrator() : rk4;
  if (feedback)
    loop.reset(0, q_start, VecX::Zero(n));
  else
    rk4.reset(0, q0, VecX::Zero(n), T);
  TrackResult r;
  std::optional<TrackCsv> csv = open_csv(a, m, N);
  const InterruptGuard interrupt;
  for (int k = 0; k <= N; ++k) {
    const double t = k * dt;
    tau(t, u);                                       // (and q_ref at t into qr)
    if (feedback) law(t, integ.q(), integ.qd(), u);  // the torque applied from t
    // |q_sim ⊖ q_ref|: rad or m (a ball's rotation: the angle of the rotation vector's entries)
    r.final_err = configuration_difference(m, qr, integ.q()).cwiseAbs().maxCoeff();
    r.max_err = std::max(r.max_err, r.final_err);
    r.max_tau = std::max(r.max_tau, u.cwiseAbs().maxCoeff());
    if (csv) csv->row(t, qr, u, integ.q());
    if (k == N) break;
    if (g_interrupted) {
      std::cerr << "femdyn track: interrupted at t = " << t << " s"
                << (csv ? "; " + escaped(csv->path()) + " was not written" : std::string()) << "\n";
      return 130;  // (the temporary file goes with `csv`)
    }
    const Status st = feedback ? loop.step() : rk4.advance_to((k + 1) * dt);
    if (!st.ok)
      throw StateError(a.positional[0] + ": " +
                       failure_text(st, loop, law, q_start, feedback, mode));
  }
  if (csv) csv->commit();
  print_track(a, m, T, N, fb, r);
  return 0;
}

}  // namespace femdyn::cli
