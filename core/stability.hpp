// Numerical diagnosis of a model at a state (femdyn check, femdyn stress; docs/stability.md):
// the conditioning of M^s, the linearised dynamics and their stiffest mode, the largest stable
// step of each explicit integrator, and bodies whose mass properties are suspicious.
//
//   cond(M^s) = λ_max / λ_min (M^s symmetric positive definite): q̈ = (M^s)⁻¹(Q − h) loses
//   about log10 cond digits to round-off.
//   Linearisation of ẏ = f(y), y = (q, q̇):  A = ∂f/∂y = [[0, I], [K, D]],  K = ∂q̈/∂q,
//   D = ∂q̈/∂q̇, by central differences of forward dynamics (4n evaluations).
//   A step h of an explicit method is stable on A when no mode λ of A, mirrored into the left
//   half-plane (λ̃ = −|Re λ| + i Im λ: a falling mode limits the step as its decaying mirror
//   does), is amplified: |R(hλ̃)| ≤ 1 with
//     RK4     R(z) = Σ_{k≤4} z^k/k!
//     dopri   R(z) = Σ_{k≤5} z^k/k! + z^6/600  (Dormand–Prince 5(4), the 5th-order solution)
//   and for symplectic Euler, which is not a Runge–Kutta map in y, the spectral radius ≤ 1 of
//   its step on the mode taken as an oscillator (ω = |λ|, ζ = |Re λ|/|λ|). Undamped modes give
//   the classical limits h ω ≤ 2.83 (RK4), ≈ 3.3 (dopri), < 2 (symplectic Euler).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "core/body_inertia.hpp"
#include "core/equations.hpp"
#include "core/integrator.hpp"

namespace femdyn {

struct MassMatrixHealth {
  double condition = 0;  // λ_max / λ_min, +inf if λ_min ≤ 0
  double lambda_min = 0, lambda_max = 0;
  double asymmetry = 0;  // ‖M − Mᵀ‖_max / ‖M‖_max
  bool positive_definite = false;
  double digits_lost() const;  // log10 cond
};
MassMatrixHealth mass_matrix_health(const MatX& Ms);

struct Linearization {
  MatX A;                         // 2n x 2n
  Eigen::VectorXcd eigenvalues;   // of A
  std::complex<double> stiffest;  // the eigenvalue of largest modulus
  double max_growth = 0;          // max Re λ (≥ 0: physical instability, e.g. falling)
  Status status;                  // a failed forward dynamics on the way
};
Linearization linearize(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau);

// The largest stable step of an explicit fixed-step or adaptive method on the linearisation,
// by bisection (relative precision 1e-6); +inf when every step is stable (no dynamics).
std::optional<double> largest_stable_step(const Linearization& lin, IntegratorKind kind);

// A body whose mass properties make the equations ill-conditioned or unphysical-looking.
struct SuspiciousBody {
  int body = -1;
  std::string name, why;
};
std::vector<SuspiciousBody> suspicious_bodies(const Model& model);

}  // namespace femdyn
