#include "core/stability.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <limits>

namespace femdyn {
namespace {

// R(z) of the Runge–Kutta methods, as the polynomial Σ c_k z^k.
std::complex<double> stability_function(IntegratorKind kind, std::complex<double> z) {
  const double rk4[] = {1, 1, 1.0 / 2, 1.0 / 6, 1.0 / 24};
  const double dopri[] = {1, 1, 1.0 / 2, 1.0 / 6, 1.0 / 24, 1.0 / 120, 1.0 / 600};
  const double* c = kind == IntegratorKind::Rk4 ? rk4 : dopri;
  const int degree = kind == IntegratorKind::Rk4 ? 4 : 6;
  std::complex<double> r = c[degree];
  for (int k = degree - 1; k >= 0; --k) r = r * z + c[k];  // Horner
  return r;
}

// Each mode λ of A, mirrored into the left half-plane (a physically growing mode, such as a
// fall, sets the same step limit as its decaying mirror), must not be amplified:
//   RK4, dopri:  |R(h λ̃)| ≤ 1,  λ̃ = −|Re λ| + i Im λ;
//   symplectic Euler on the mode as an oscillator x'' + 2ζω x' + ω² x = 0 (ω = |λ|,
//   ζ = |Re λ|/|λ|): spectral radius of [[1 − h²ω², h(1 − 2hζω)], [−hω², 1 − 2hζω]] ≤ 1.
bool stable(const Linearization& lin, IntegratorKind kind, double h) {
  constexpr double slack = 1 + 1e-12;
  for (Eigen::Index i = 0; i < lin.eigenvalues.size(); ++i) {
    const std::complex<double> lambda(-std::abs(lin.eigenvalues[i].real()),
                                      lin.eigenvalues[i].imag());
    if (kind != IntegratorKind::Euler) {
      if (std::abs(stability_function(kind, h * lambda)) > slack) return false;
      continue;
    }
    const double w = std::abs(lambda), zeta = w > 0 ? -lambda.real() / w : 0;
    Eigen::Matrix2d G;
    G << 1 - h * h * w * w, h * (1 - 2 * h * zeta * w), -h * w * w, 1 - 2 * h * zeta * w;
    if (Eigen::EigenSolver<Eigen::Matrix2d>(G, false).eigenvalues().cwiseAbs().maxCoeff() > slack)
      return false;
  }
  return true;
}

}  // namespace

double MassMatrixHealth::digits_lost() const {
  return std::isfinite(condition) ? std::log10(condition) : std::numeric_limits<double>::infinity();
}

MassMatrixHealth mass_matrix_health(const MatX& Ms) {
  MassMatrixHealth h;
  const double scale = Ms.cwiseAbs().maxCoeff();
  h.asymmetry = scale > 0 ? (Ms - Ms.transpose()).cwiseAbs().maxCoeff() / scale : 0;
  const Eigen::SelfAdjointEigenSolver<MatX> eig(Ms, Eigen::EigenvaluesOnly);
  h.lambda_min = eig.eigenvalues().minCoeff();
  h.lambda_max = eig.eigenvalues().maxCoeff();
  h.positive_definite = h.lambda_min > 0;
  h.condition =
      h.positive_definite ? h.lambda_max / h.lambda_min : std::numeric_limits<double>::infinity();
  return h;
}

Linearization linearize(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau) {
  const int n = m.n();
  Linearization lin;
  lin.A = MatX::Zero(2 * n, 2 * n);
  lin.A.topRightCorner(n, n).setIdentity();
  VecX qp = q, qdp = qd, plus(n);
  // Column j of [K D] by central differences: (q̈(y + δ e_j) − q̈(y − δ e_j)) / 2δ.
  for (int j = 0; j < 2 * n; ++j) {
    VecX& x = j < n ? qp : qdp;
    const int i = j % n;
    const double x0 = x[i], delta = 1e-6 * std::max(1.0, std::abs(x0));
    for (int side : {1, -1}) {
      x[i] = x0 + side * delta;
      lin.status = forward_dynamics(m, ws, qp, qdp, tau);
      if (!lin.status.ok) return lin;
      if (side == 1)
        plus = ws.qdd;
      else
        lin.A.block(n, j, n, 1) = (plus - ws.qdd) / (2 * delta);
    }
    x[i] = x0;
  }
  lin.eigenvalues = Eigen::EigenSolver<MatX>(lin.A, false).eigenvalues();
  for (Eigen::Index i = 0; i < lin.eigenvalues.size(); ++i) {
    if (std::abs(lin.eigenvalues[i]) > std::abs(lin.stiffest)) lin.stiffest = lin.eigenvalues[i];
    lin.max_growth = std::max(lin.max_growth, lin.eigenvalues[i].real());
  }
  return lin;
}

std::optional<double> largest_stable_step(const Linearization& lin, IntegratorKind kind) {
  if (kind == IntegratorKind::Bdf) return std::numeric_limits<double>::infinity();
  const double rate = std::abs(lin.stiffest);
  if (rate == 0) return std::numeric_limits<double>::infinity();
  // Every explicit method here is unstable beyond h |λ| = 10; bisect on log h below that.
  double lo = 1e-6 / rate, hi = 10 / rate;
  if (!stable(lin, kind, lo)) return 0.0;
  if (stable(lin, kind, hi)) return hi;
  while (hi / lo > 1 + 1e-6) {
    const double mid = std::sqrt(lo * hi);
    (stable(lin, kind, mid) ? lo : hi) = mid;
  }
  return lo;
}

std::vector<SuspiciousBody> suspicious_bodies(const Model& m) {
  std::vector<SuspiciousBody> out;
  const int nb = static_cast<int>(m.bodies.size());
  std::vector<MassProperties> p(nb);
  for (int b = 0; b < nb; ++b) p[b] = body_mass_properties(m, b);
  const auto flag = [&](int b, const std::string& why) {
    out.push_back({b, m.bodies[b].name, why});
  };
  for (int b = 0; b < nb; ++b) {
    // Neighbours: the parent and the children, among bodies that carry mass.
    double heaviest = 0;
    std::string heaviest_name;
    for (int c = 0; c < nb; ++c) {
      const bool neighbour = c == m.bodies[b].parent || m.bodies[c].parent == b;
      if (neighbour && p[c].mass > heaviest) {
        heaviest = p[c].mass;
        heaviest_name = m.bodies[c].name;
      }
    }
    const double mass = p[b].mass;
    if (mass > 0 && heaviest > 0 && mass < 1e-6 * heaviest)
      flag(b, "near-zero mass: " + format_short(mass) + " kg, " + format_short(mass / heaviest) +
                  " of its neighbour '" + heaviest_name + "' (" + format_short(heaviest) +
                  " kg); where nothing heavier hangs "
                  "beyond it M^s loses about " +
                  format_short(std::log10(heaviest / mass)) +
                  " digits: merge it into its neighbour or give it a realistic mass");
    if (mass <= 0) continue;
    const Mat3 Ic = p[b].inertia_com();
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (Ic + Ic.transpose()));
    const Vec3 I = eig.eigenvalues();  // ascending
    if (I[2] <= 0) continue;           // a point mass: no rotational inertia by design
    if (I[0] < 1e-9 * I[2])
      flag(b, "near-zero principal inertia: " + format_short(I[0]) + " kg·m² against " +
                  format_short(I[2]) +
                  " (a thin rod or a point): rotations about that axis are ill-conditioned");
    else if (I[0] + I[1] - I[2] < 1e-6 * I[2])
      flag(b, "inertia nearly violates the triangle inequality (I1 + I2 − I3 = " +
                  format_short(I[0] + I[1] - I[2]) + " kg·m², I3 = " + format_short(I[2]) +
                  "): a flat body at best, or a mistyped tensor");
  }
  return out;
}

}  // namespace femdyn
