#include "sim/controller_diagnosis.hpp"

#include <unsupported/Eigen/MatrixFunctions>

#include "core/model/names.hpp"
#include "sim/stability.hpp"

namespace femdyn {
namespace {

constexpr int kLargest = 200;        // n beyond it: no verdict (dense exponentials of 3n)
constexpr double kGrows = 1 + 1e-6;  // a spectral radius above it grows per period

double spectral_radius(const MatX& G) {
  return G.size() ? Eigen::EigenSolver<MatX>(G, false).eigenvalues().cwiseAbs().maxCoeff() : 0.0;
}

// ρ(Φ + Γ K) and ρ(Φ) for the hold over T (Van Loan's block exponential).
std::pair<double, double> held_radii(const MatX& A, const MatX& B, const MatX& K, double T) {
  const Eigen::Index m = A.rows(), n = B.cols();
  MatX C = MatX::Zero(m + n, m + n);
  C.topLeftCorner(m, m) = A * T;
  C.topRightCorner(m, n) = B * T;
  const MatX E = C.exp();
  const MatX Phi = E.topLeftCorner(m, m), Gamma = E.topRightCorner(m, n);
  return {spectral_radius(Phi + Gamma * K), spectral_radius(Phi)};
}

Linearization linearization_of(MatX A) {
  Linearization lin;
  lin.eigenvalues = Eigen::EigenSolver<MatX>(A, false).eigenvalues();
  for (Eigen::Index i = 0; i < lin.eigenvalues.size(); ++i) {
    if (std::abs(lin.eigenvalues[i]) > std::abs(lin.stiffest)) lin.stiffest = lin.eigenvalues[i];
    lin.max_growth = std::max(lin.max_growth, lin.eigenvalues[i].real());
  }
  lin.A = std::move(A);
  return lin;
}

}  // namespace

MatX controller_gain(const Model& m, const Control& u, double t, const VecX& q, const VecX& v) {
  const Eigen::Index n = m.n();
  MatX K(n, 2 * n);
  VecX plus(n), minus(n), qp = q, vp = v;
  for (Eigen::Index j = 0; j < 2 * n; ++j) {
    VecX& y = j < n ? qp : vp;
    const Eigen::Index i = j < n ? j : j - n;
    const double h = 1e-6 * std::max(1.0, std::abs(y[i])), y0 = y[i];
    y[i] = y0 + h;
    u(t, qp, vp, plus);
    y[i] = y0 - h;
    u(t, qp, vp, minus);
    y[i] = y0;
    K.col(j) = (plus - minus) / (2 * h);
  }
  return K;
}

ControlledLoop controlled_loop(const Model& m, const VecX& q, const VecX& v, const VecX& tau,
                               const MatX& K, double period, bool held, IntegratorKind kind,
                               double dt) {
  ControlledLoop r;
  const Eigen::Index n = m.n();
  if (m.n_q() != n || !m.constraints.empty() || n > kLargest || n == 0) {
    r.status = {false,
                "no verdict: the model's q is not a vector space, or it has closed loops, "
                "or n > 200"};
    return r;
  }
  Workspace ws(m);
  const Linearization plant = linearize(m, ws, q, v, tau, 0);
  if (!plant.status.ok) {
    r.status = plant.status;
    return r;
  }
  evaluate(m, ws, q, v, tau);
  MatX B = MatX::Zero(2 * n, n);
  B.bottomRows(n) = ws.Ms.ldlt().solve(MatX::Identity(n, n));  // ∂q̈/∂τ = (M^s)⁻¹
  const Linearization closed = linearization_of(plant.A + B * K);
  r.plant_stiffest = std::abs(plant.stiffest);
  r.plant_growth = plant.max_growth;
  r.stiffest = std::abs(closed.stiffest);
  r.growth = closed.max_growth;
  r.dt = dt;
  if (dt > 0) {
    r.plant_stable_step = largest_stable_step(plant, kind).value_or(0);
    r.closed_stable_step = largest_stable_step(closed, kind).value_or(0);
  }
  if (held) {
    std::tie(r.radius, r.plant_radius) = held_radii(plant.A, B, K, period);
    // A shorter period that holds the loop: halvings to 1e-9 T, then bisection on log T.
    // (Each ρ is computed once: the one at T is r.radius.)
    const auto holds = [&](double T) { return held_radii(plant.A, B, K, T).first <= kGrows; };
    double lo = period, hi = period;
    bool held_at_lo = r.radius <= kGrows;
    for (int k = 0; k < 30 && !held_at_lo; ++k) {
      hi = lo;
      lo /= 2;
      held_at_lo = holds(lo);
    }
    if (held_at_lo) {
      for (int i = 0; i < 30 && hi / lo > 1.01; ++i) {
        const double mid = lo * std::sqrt(hi / lo);
        (holds(mid) ? lo : hi) = mid;
      }
      r.stable_period = lo;
    }
  }
  return r;
}

std::string controller_cause(const ControlledLoop& r, double period, bool held) {
  if (!r.status.ok) return {};
  const std::string modes = "closed-loop stiffest mode " + format_short(r.stiffest) +
                            " 1/s, the model's with τ held " + format_short(r.plant_stiffest) +
                            " 1/s";
  if (held && r.radius > std::max(kGrows, r.plant_radius * kGrows)) {
    std::string text =
        "the controller is the likely cause: at the run's start its gain makes "
        "the loop sampled every " +
        format_short(period) + " s grow ×" + format_short(r.radius) +
        " a period (the spectral radius of e^{AT} + Γ K; the model with the start's τ held ×" +
        format_short(r.plant_radius) + "; " + modes + "): lower its gains or add damping";
    if (r.stable_period > 0)
      text += ", or sample faster (these gains hold below a period of about " +
              format_short(r.stable_period) + " s)";
    else
      text += " (no period down to 1e-9 of this one holds these gains)";
    return text;
  }
  if (!held && r.growth > r.plant_growth + 1e-6 * std::max(1.0, r.plant_stiffest) && r.growth > 0)
    return "the controller is the likely cause: at the run's start its gain makes the closed "
           "loop grow at " +
           format_short(r.growth) + " 1/s (the model alone " + format_short(r.plant_growth) +
           " 1/s; " + modes + "): lower its gains or add damping";
  if (!held && r.dt > r.closed_stable_step && r.dt <= r.plant_stable_step)
    return "the controller is the likely cause: its gain stiffens the loop (" + modes +
           ") beyond the stability limit of the step " + format_short(r.dt) + " s (" +
           format_short(r.closed_stable_step) + " s with the controller, " +
           format_short(r.plant_stable_step) + " s without): lower its gains, or a smaller step";
  return {};
}

std::string controller_divergence(const Model& m, const Control& u, double t, const VecX& q,
                                  const VecX& v, double period, bool held, IntegratorKind kind,
                                  double dt) {
  try {
    if (m.n_q() != m.n() || !m.constraints.empty() || m.n() > kLargest) return {};
    VecX tau(m.n());
    u(t, q, v, tau);
    const MatX K = controller_gain(m, u, t, q, v);
    if (!K.allFinite() || !tau.allFinite()) return {};
    return controller_cause(controlled_loop(m, q, v, tau, K, period, held, kind, dt), period, held);
  } catch (...) {  // (the report goes on without the clause)
    return {};
  }
}

}  // namespace femdyn
