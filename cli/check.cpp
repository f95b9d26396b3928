// femdyn check MODEL: the numerical diagnosis of a user's model (core/stability.hpp) over
// sampled states: conditioning of M^s, the stiffest mode and the largest stable step of each
// explicit integrator, suspicious bodies, and a recommended integrator and step.
#include <cmath>
#include <complex>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>

#include "cli/commands.hpp"
#include "core/sampling.hpp"
#include "core/stability.hpp"
#include "io/output.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kHelp =
    R"(usage: femdyn check MODEL [--states K] [--seed S] [--json] [--gravity gx,gy,gz]

Diagnoses the model at K seeded states (default 10: q = 0 at rest, then q within the joint
limits and q̇ in ±1):
  - cond(M^s) = λ_max/λ_min over the states (q̈ loses about log10 cond digits), symmetry and
    positive definiteness;
  - the stiffest mode: the eigenvalue of largest modulus of the linearised dynamics
    A = ∂(q̇, q̈)/∂(q, q̇) (central differences of forward dynamics), and from A the largest
    stable step of rk4, euler (symplectic) and dopri, the smallest over the states;
  - bodies with suspicious mass properties, by name: near-zero mass or a mass ratio beyond 1e6
    to a neighbour, a near-zero principal inertia, an inertia that nearly violates the triangle
    inequality;
  - a recommended integrator and step (docs/stability.md).
Exit 1 when M^s is singular at a sampled state or a body is flagged.
)";

// What an eigenvalue of the linearised dynamics is, in words.
std::string mode_text(std::complex<double> l) {
  const double r = std::abs(l);
  if (r == 0) return "no dynamics";
  if (std::abs(l.imag()) <= 1e-9 * r)
    return l.real() > 0 ? "real, growing: a fall or an unstable equilibrium"
                        : "real, decaying: overdamped";
  return "oscillatory, damping ratio " + format_short(-l.real() / r);
}

}  // namespace

int cmd_check(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"}, {"states", "seed", "gravity"});
  if (a.has("help")) {
    std::cout << kHelp;
    return 0;
  }
  const Model m = load(a);
  const int K = static_cast<int>(integer_option(a, "states", 10, 1, 10000));
  std::mt19937 rng(static_cast<unsigned>(integer_option(a, "seed", 1, 0, 4294967295.0)));
  const int n = m.n();
  Workspace ws(m);
  const VecX tau = VecX::Zero(n);

  double cond_lo = std::numeric_limits<double>::infinity(), cond_hi = 0, asym = 0;
  int singular_states = 0;
  std::string singular_message;
  double stiffest = 0;
  std::complex<double> stiffest_lambda;
  const IntegratorKind explicit_kinds[] = {IntegratorKind::Rk4, IntegratorKind::Euler,
                                           IntegratorKind::Dopri};
  double h_max[3] = {INFINITY, INFINITY, INFINITY};
  bool h_known[3] = {true, true, true};
  for (int k = 0; k < K; ++k) {
    const VecX q = k == 0 ? VecX::Zero(n) : random_posture(m, rng);
    const VecX qd = k == 0 ? VecX::Zero(n) : random_uniform(n, 1.0, rng);
    evaluate(m, ws, q, qd, tau);
    const MassMatrixHealth h = mass_matrix_health(ws.Ms);
    asym = std::max(asym, h.asymmetry);
    cond_lo = std::min(cond_lo, h.condition);
    cond_hi = std::max(cond_hi, h.condition);
    if (!h.positive_definite) {
      ++singular_states;
      const Status st = ws.solver.factorize(ws.Ms);
      if (singular_message.empty()) singular_message = st.ok ? "λ_min ≤ 0" : st.message;
      continue;
    }
    const Linearization lin = linearize(m, ws, q, qd, tau);
    if (!lin.status.ok) continue;
    if (std::abs(lin.stiffest) > stiffest) {
      stiffest = std::abs(lin.stiffest);
      stiffest_lambda = lin.stiffest;
    }
    for (int i = 0; i < 3; ++i) {
      const auto hs = largest_stable_step(lin, explicit_kinds[i]);
      if (!hs)
        h_known[i] = false;
      else
        h_max[i] = std::min(h_max[i], *hs);
    }
  }
  const std::vector<SuspiciousBody> bodies = suspicious_bodies(m);

  // Recommendation: explicit methods while their stable step is not the binding constraint.
  std::string recommendation;
  if (singular_states > 0)
    recommendation = "none: M^s is singular at " + std::to_string(singular_states) +
                     " of the states; repair the model first";
  else if (h_max[0] < 1e-4)
    recommendation = "bdf (e.g. --rtol 1e-6): the stiffest mode limits rk4 to dt < " +
                     format_short(h_max[0]) + " s and dopri to steps < " + format_short(h_max[2]) +
                     " s";
  else if (std::isfinite(h_max[0]))
    recommendation = "dopri (--rtol 1e-6) for accuracy; for a fixed-rate loop rk4 with dt <= " +
                     format_short(h_max[0] / 2) + " s (half its stability limit)";
  else
    recommendation = "dopri (--rtol 1e-6); no stiff mode was found";

  if (a.has("json")) {
    Json j = {{"model", m.name},
              {"n", n},
              {"coordinates", m.coordinate_names},
              {"states", K},
              {"condition", {{"min", cond_lo}, {"max", cond_hi}}},
              {"digits_lost", std::log10(cond_hi)},
              {"asymmetry", asym},
              {"singular_states", singular_states},
              {"stiffest_mode", stiffest},
              {"stiffest_kind", mode_text(stiffest_lambda)},
              {"recommendation", recommendation}};
    Json steps = Json::object();
    for (int i = 0; i < 3; ++i)
      steps[integrator_name(explicit_kinds[i])] =
          h_known[i] && std::isfinite(h_max[i]) ? Json(h_max[i]) : Json(nullptr);
    j["largest_stable_step"] = steps;
    Json flagged = Json::array();
    for (const auto& b : bodies) flagged.push_back({{"body", b.name}, {"why", b.why}});
    j["suspicious_bodies"] = flagged;
    if (!singular_message.empty()) j["singular"] = singular_message;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "model: " << m.name << " (" << n << " coordinates, " << m.bodies.size()
              << " bodies), " << K << " states\n";
    if (singular_states)
      std::cout << "M^s: singular at " << singular_states << " of " << K
                << " states: " << singular_message << "\n";
    if (singular_states < K)
      std::cout << "M^s: cond from " << format_short(cond_lo) << " to " << format_short(cond_hi)
                << " (q̈ loses up to " << format_short(std::log10(cond_hi))
                << " digits of 16), symmetric to " << format_short(asym)
                << (singular_states ? "" : ", positive definite at every state") << "\n";
    std::cout << "stiffest mode: |λ| = " << format_short(stiffest) << " rad/s ("
              << mode_text(stiffest_lambda) << ")\nlargest stable step:";
    for (int i = 0; i < 3; ++i)
      std::cout << " " << integrator_name(explicit_kinds[i]) << " "
                << (!h_known[i]               ? std::string("n/a (n > 200)")
                    : std::isfinite(h_max[i]) ? format_short(h_max[i]) + " s"
                                              : std::string("unlimited"))
                << (i < 2 ? "," : "");
    std::cout << " (bdf: unlimited)\n";
    if (bodies.empty()) std::cout << "suspicious bodies: none\n";
    for (const auto& b : bodies)
      std::cout << "suspicious body '" << b.name << "': " << b.why << "\n";
    std::cout << "recommended: " << recommendation << "\n";
  }
  return singular_states > 0 || !bodies.empty() ? 1 : 0;
}

}  // namespace femdyn::cli
