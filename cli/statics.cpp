// femdyn statics: where the mechanism rests under its springs, gravity, loads and τ
// (sim/statics.hpp): Newton with the analytic stiffness and continuation in the load.
#include "sim/statics.hpp"

#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "core/dynamics/equations.hpp"
#include "core/model/names.hpp"
#include "io/output.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kStaticsHelp =
    R"(usage: femdyn statics MODEL [--tau …] [--load BODY:fx,fy,fz[,tx,ty,tz][@x,y,z];…]
                      [--q0 …] [--tolerance R] [--json] [--gravity gx,gy,gz]

The configuration q at which the mechanism rests (q̇ = 0, q̈ = 0) under its springs, gravity,
the model's loads, the joint forces --tau (n values) and the loads --load: each a force (N,
world axes, fixed in direction) and optionally a torque (N m) on BODY at the point x, y, z of
its frame (default its origin), several separated by ';'. It solves
  r(q) = τ − τ_id(q, 0, 0) = 0,   τ_id(q, 0, 0) = −Q(q),
by Newton's method with the analytic stiffness ∂τ_id/∂q (a Levenberg–Marquardt step where it is
singular: a pendulum started horizontal), each step halved until the residual falls, and continuation in the load: gravity, the loads and τ are scaled by λ from 0 to 1 in
steps that halve where Newton fails (large deflections) and double where it converges. From
--q0 (n_q values), else the neutral configuration. Converged when |r|∞ ≤ R times the largest
force met (--tolerance, default 1e-10). No equilibrium found (a coordinate nothing holds, a load
beyond what the springs can bear) is a failure naming the load factor reached, exit 1.
A model with closed loops (constraints) starts from q0 assembled onto them and solves
r(q) + Phi_q^T mu = 0 on Phi(q) = 0 for q and the constraint forces mu, each Newton step
followed by the projection back onto the loops (docs/loops.md); r is then the force no
constraint carries.

Prints the load steps, Newton steps and residual, q by coordinate name and each body's origin
in the world (with loops also |Phi| and the constraint forces mu by equation); --json gives
{"coordinates", "q", "residual", "scale", "load_steps", "iterations", "bodies": {name: [x, y,
z]}} and with loops "constraint_residual" and "multipliers" [{"equation", "mu"}].
)";

// "BODY:fx,fy,fz[,tx,ty,tz][@x,y,z]" items separated by ';'.
std::vector<LoadSpec> parse_loads(const std::string& text) {
  std::vector<LoadSpec> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    const std::string item = text.substr(start, end - start);
    start = end + 1;
    const std::size_t colon = item.find(':'), at = item.find('@');
    if (colon == std::string::npos)
      throw CliError("--load: expected BODY:fx,fy,fz[,tx,ty,tz][@x,y,z], got " + echo_text(item));
    LoadSpec l;
    l.body = item.substr(0, colon);
    l.where = "--load " + echo_text(item);
    const std::vector<double> f = parse_numbers(
        "load",
        item.substr(colon + 1, at == std::string::npos ? std::string::npos : at - colon - 1));
    if (f.size() != 3 && f.size() != 6)
      throw CliError("--load " + echo_text(item) +
                     ": expected 3 force or 6 force and torque values");
    l.force = Vec3(f[0], f[1], f[2]);
    if (f.size() == 6) l.torque = Vec3(f[3], f[4], f[5]);
    if (at != std::string::npos) {
      const std::vector<double> p = parse_numbers("load", item.substr(at + 1));
      if (p.size() != 3) throw CliError("--load " + echo_text(item) + ": expected @x,y,z");
      l.point = Vec3(p[0], p[1], p[2]);
    }
    out.push_back(l);
  }
  return out;
}

Json body_origins(const Model& m, const VecX& q) {
  Workspace ws(m);
  const VecX zero = VecX::Zero(m.n());
  inverse_dynamics(m, ws, q, zero, zero);  // (the poses at q)
  Json out = Json::object();
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    out[m.bodies[b].name] = vector_json(ws.origin + ws.body[b].p);
  return out;
}

}  // namespace

int cmd_statics(int argc, char** argv) {
  const Args a =
      parse_args(argc, argv, 2, {"help", "json"}, {"gravity", "tau", "load", "q0", "tolerance"});
  if (a.has("help")) {
    std::cout << kStaticsHelp;
    return 0;
  }
  const Model m = load(a);  // (checks the file and the model once, with the usual messages)
  StaticsOptions o;
  o.tau = a.has("tau") ? state_vector(a, "tau", m) : VecX();
  if (a.has("q0")) o.q0 = configuration_vector(a, "q0", m);
  if (a.has("load")) o.loads = parse_loads(a.options.at("load"));
  o.tolerance = number_option(a, "tolerance", 1e-10);
  if (!(o.tolerance > 0 && o.tolerance < 1)) throw CliError("--tolerance expects R in (0, 1)");
  const StaticsResult r = solve_statics(read_spec(a.positional[0], load_options(a)), o);
  if (!r.status.ok) {
    std::cerr << "femdyn statics: " << escaped(a.positional[0]) << ": "
              << safe_message(r.status.message) << "\n";
    return 1;
  }
  const Json bodies = body_origins(m, r.q);
  Json multipliers = Json::array();  // with loops: μ by constraint equation
  for (Eigen::Index i = 0; i < r.multipliers.size(); ++i)
    multipliers.push_back(
        {{"equation", constraint_row_name(m, static_cast<int>(i))}, {"mu", r.multipliers[i]}});
  if (a.has("json")) {
    Json j{{"coordinates", m.coordinate_names},
           {"q", vector_json(r.q)},
           {"residual", r.residual},
           {"scale", r.scale},
           {"load_steps", r.load_steps},
           {"iterations", r.iterations},
           {"bodies", bodies}};
    if (!m.constraints.empty())
      j["constraint_residual"] = r.constraint_residual, j["multipliers"] = multipliers;
    std::cout << readable_json(j);
    return 0;
  }
  std::ostringstream text;
  text.precision(12);
  text << "equilibrium in " << r.load_steps << " load step(s), " << r.iterations
       << " Newton step(s); |r| = " << r.residual << " (largest force " << r.scale << ")\n";
  for (int i = 0; i < m.n_q(); ++i)
    text << "  " << m.configuration_names[i] << " = " << r.q[i] << "\n";
  text << "body origins (world):\n";
  for (const auto& [name, p] : bodies.items())
    text << "  " << name << " = [" << p[0].get<double>() << ", " << p[1].get<double>() << ", "
         << p[2].get<double>() << "]\n";
  if (!m.constraints.empty()) {
    text << "loops: |Phi| = " << r.constraint_residual << "; constraint forces mu:\n";
    for (const Json& x : multipliers)
      text << "  " << x["equation"].get<std::string>() << " = " << x["mu"].get<double>() << "\n";
  }
  std::cout << text.str();
  return 0;
}

}  // namespace femdyn::cli
