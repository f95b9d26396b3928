// femdyn track: computed-torque feed-forward along a smooth point-to-point motion, replayed
// open loop in forward simulation — the control use of the equations.
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "io/csv.hpp"
#include "io/output.hpp"
#include "sim/fixed_step.hpp"
#include "sim/quintic.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kHelp =
    R"(usage: femdyn track MODEL --to a,b,… [--from …] [--duration T] [--steps N] [--csv FILE [--force]] [--json]
                     [--gravity gx,gy,gz]

Plans the quintic (minimum-jerk) motion q_ref(t) from --from (default 0, the identity rotation
for a ball or free joint) to --to in T seconds (default 1), along each joint's geodesic
(q_ref = q_from ⊕ s(t/T)(q_to ⊖ q_from); n_q values each, quaternions (w, x, y, z)), computes the joint torques τ(t) = M^s q̈_ref + h − Q(τ = 0) by inverse dynamics,
then simulates the model under τ(t) alone (RK4, N steps, default 1000) and reports how closely
the simulated motion follows q_ref (max |q_sim ⊖ q_ref|: rad or m; a rotation by the rotation
vector between the two quaternions). --csv writes t, q_ref, τ and q_sim per step (atomically; an
existing FILE is replaced only with --force, and never when it is MODEL). --json prints
{"model", "n", "coordinates", "duration", "steps", "max_tracking_error", "max_abs_tau"}.
)";

}  // namespace

int cmd_track(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json", "force"},
                            {"to", "from", "duration", "steps", "csv", "gravity"});
  if (a.has("help")) {
    std::cout << kHelp;
    return 0;
  }
  if (a.has("csv")) {  // refused before any work if it would clobber a file
    const std::string& out = a.options.at("csv");
    std::error_code ec;
    if (std::filesystem::equivalent(out, a.positional.at(0), ec))
      throw CliError("--csv " + out + " is the model file itself");
    if (std::filesystem::exists(out, ec) && !a.has("force"))
      throw CliError("--csv " + out + ": exists (use --force to replace it)");
  }
  const Model m = load(a);
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
  Rk4 rk4(m, {.dt = dt}, tau);
  rk4.reset(0, q0, VecX::Zero(n), T);
  double max_err = 0, max_tau = 0;
  std::ostringstream csv;
  csv.precision(12);
  csv << "t";
  // Names quoted where they need it (RFC 4180): a coordinate "a,b" stays one column.
  for (const auto& c : m.configuration_names) csv << ',' << csv_field("q_ref_" + c);
  for (const auto& c : m.coordinate_names) csv << ',' << csv_field("tau_" + c);
  for (const auto& c : m.configuration_names) csv << ',' << csv_field("q_sim_" + c);
  csv << "\n";
  for (int k = 0; k <= N; ++k) {
    const double t = k * dt;
    tau(t, u);
    // |q_sim ⊖ q_ref|: rad or m (a ball's rotation: the angle of the rotation vector's entries)
    max_err = std::max(max_err, configuration_difference(m, qr, rk4.q()).cwiseAbs().maxCoeff());
    max_tau = std::max(max_tau, u.cwiseAbs().maxCoeff());
    csv << t;
    for (int i = 0; i < m.n_q(); ++i) csv << "," << qr[i];
    for (int i = 0; i < n; ++i) csv << "," << u[i];
    for (int i = 0; i < m.n_q(); ++i) csv << "," << rk4.q()[i];
    csv << "\n";
    if (k == N) break;
    const Status st = rk4.advance_to((k + 1) * dt);
    if (!st.ok) throw CliError(st.message);
  }
  if (a.has("csv")) {
    try {
      write_file_atomic(a.options.at("csv"), csv.str(), a.has("force"));
    } catch (const std::runtime_error& e) {
      throw CliError(std::string("--csv ") + e.what());
    }
  }
  if (a.has("json")) {
    std::cout << json_text(Json{{"model", m.name},
                                {"n", m.n()},
                                {"coordinates", m.coordinate_names},
                                {"duration", T},
                                {"steps", N},
                                {"max_tracking_error", max_err},
                                {"max_abs_tau", max_tau}})
              << "\n";
  } else {
    std::cout << "model: " << m.name << "\nquintic motion over " << T << " s, " << N
              << " RK4 steps, feed-forward torques by inverse dynamics\n"
              << "max |tau|: " << max_tau << "\nmax |q_sim - q_ref|: " << max_err << "\n";
  }
  return 0;
}

}  // namespace femdyn::cli
