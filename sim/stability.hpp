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
//   and for semi-implicit Euler, which is not a Runge–Kutta map in y, the spectral radius ≤ 1
//   of its step on each oscillator x″ = k x + d ẋ that a pair of modes makes (k = −λ1 λ2,
//   d = λ1 + λ2: a complex pair, or two real modes of one shape). Undamped modes give the
//   classical limits h ω ≤ 2.83 (RK4), ≈ 3.3 (dopri), < 2 (semi-implicit Euler); an overdamped
//   spring's fast mode λ gives |λ| h ≤ 2.785 (RK4) and about 2 (Euler).
#pragma once
#include <cmath>
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/equations.hpp"
#include "sim/integrator.hpp"

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
// Closed loops: q̈ of the constrained equations at Baumgarte's rate `baumgarte`, whose pair −ω
// per independent equation is then among the eigenvalues (the block of the constraint's own
// dynamics Φ̈ + 2ωΦ̇ + ω²Φ = 0, which the tangent motion does not feed); at 0 those are zeros
// and the rest are the mechanism's own modes on its loops.
// A is analytic (core/derivatives/derivatives.hpp: ∂q̈/∂q, ∂q̈/∂v and the chart block, in the chart
// ξ ↦ q ⊕ ξ; closed loops by core/derivatives/loops.hpp at this rate) where the derivatives
// cover the model; otherwise difference_linearization's.
Linearization linearize(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau, double baumgarte = Motion::kDefaultBaumgarte);
// ∂q̈/∂(q, v) by central differences of forward dynamics (2n pairs of evaluations, step 1e-6
// relative), in the same chart, for every model; the chart block ∂ξ̇/∂ξ is each joint type's own
// (chart_rate_jacobian), as in linearize.
Linearization difference_linearization(const Model& model, Workspace& ws, const VecX& q,
                                       const VecX& qd, const VecX& tau,
                                       double baumgarte = Motion::kDefaultBaumgarte);

// Closed loops: how near q is to a dead point, σ_rank / σ_1 of the constraint Jacobian Φ_q's
// singular values (its first `rank`: the redundant equations' zeros left out); +inf without
// constraints or at rank 0. femdyn check reports the smallest over its states, femdyn stress
// over a run; below about 1e-6 the constraint forces are large, and at 0 the motion fails.
double dead_point_ratio(const Model& model, const VecX& q, int rank);

// The largest stable step of an explicit fixed-step or adaptive method on the linearisation,
// by bisection (relative precision 1e-6); +inf when every step is stable (no dynamics).
std::optional<double> largest_stable_step(const Linearization& lin, IntegratorKind kind);

// What a mode (an eigenvalue λ of A) is (docs/stability.md#modes):
//   oscillatory   a complex pair: natural frequency ω = |λ|; a damping ratio ζ = −Re λ / |λ| ≥ 0
//                 only where the model dissipates (joint dampers). In a conservative model the
//                 mode is undamped, and a real part at a moving state comes from the velocity
//                 terms of the linearisation there, not from damping (ζ is then NaN).
//   saddle        a real pair ±λ: an unstable equilibrium (the mechanism falls away from it at
//                 the rate |λ|);
//   decaying      real, negative, alone: an overdamped (dissipative) mode, time constant 1/|λ|;
//   growing       real, positive, alone: a fall, or the motion at that state pulling away;
//   none          λ = 0: no restoring force on that coordinate.
enum class ModeKind { None, Oscillatory, Saddle, Decaying, Growing };
struct Mode {
  std::complex<double> lambda;
  ModeKind kind = ModeKind::None;
  double omega = 0;     // |λ| (rad/s)
  double zeta = NAN;    // damping ratio, where it is one (oscillatory, dissipative model)
  int coordinate = -1;  // the coordinate that moves most in the mode (its eigenvector's q part)
  bool dissipative() const { return kind == ModeKind::Decaying || (zeta >= 0.5); }
  std::string text() const;  // e.g. "oscillatory, undamped (a conservative model)"
};
// The modes of a linearisation, stiffest first; `dissipative_model`: the model has dampers.
std::vector<Mode> modes(const Linearization& lin, bool dissipative_model);
bool has_dampers(const Model& model);

// The largest step that resolves an oscillation of ω (rad/s) to a relative error `tol` per
// period (docs/stability.md#accuracy), from the method's error on x″ = −ω² x with N steps a
// period (hω = 2π/N):
//   rk4    phase error per period (2π)⁵ / (120 N⁴)      → N = ((2π)⁵ / (120 tol))^¼
//   euler  orbit distortion hω/2 = π/N per step (its phase error (2π)³/(24 N²) is smaller)
//                                                        → N = max(π/tol, √((2π)³/(24 tol)))
// dt = 2π / (N ω). dopri and bdf: 0 (their steps follow their tolerance).
double resolving_step(IntegratorKind kind, double omega, double tol);
// The relative error per period that step dt gives on an oscillation of ω (the inverse of the
// rule above, the larger of its terms).
double error_per_period(IntegratorKind kind, double omega, double dt);

// The cause of a diverged run of `kind` (at fixed step dt, or adaptive with dt = 0 and its
// `setting`), for its one-line message: the stiffest mode of the linearisation at the start
// state and the step limit and step it gives, e.g. "rk4 at dt = 1.5 s is beyond the stability
// limit of the stiffest mode (10 rad/s, oscillatory, undamped; limit ≈ 0.283 s); use dt ≤
// 0.037 s or dopri".
// Closed loops are linearised at the run's Baumgarte rate, whose modes −ω are among the stiffest.
std::string divergence_cause(const Model& model, IntegratorKind kind, double dt,
                             const std::string& setting, const VecX& q0, const VecX& qd0,
                             const VecX& tau0, double baumgarte = Motion::kDefaultBaumgarte);

// The largest stable step of `kind` on a closed loop's residual at Baumgarte's rate ω, the mode
// ë + 2ω ė + ω² e = 0 (a double eigenvalue −ω) by the same test as the model's modes: rk4 about
// 2.785/ω, symplectic Euler (2√2 − 2)/ω, dopri about 3.3/ω, bdf unbounded.
std::optional<double> baumgarte_stable_step(double omega, IntegratorKind kind);

// A body whose mass properties make the equations ill-conditioned or unphysical-looking.
struct SuspiciousBody {
  int body = -1;
  std::string name, why;
  bool note = false;  // a physically valid edge case worth knowing (a flat body), not a fault
};
std::vector<SuspiciousBody> suspicious_bodies(const Model& model);

}  // namespace femdyn
