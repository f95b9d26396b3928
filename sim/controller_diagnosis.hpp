// Whether a controller drove a run to diverge (docs/control.md#when-a-controlled-run-diverges).
// At the run's start state the model is linearised with τ held (A, sim/stability.hpp) and the
// controller's gain K = ∂u/∂(q, q̇) (n x 2n) is taken by central differences of u; with
// B = [0; (M^s)⁻¹] the closed loop is
//
//   u inside f (per evaluation):  ẋ = (A + B K) x;
//   u held over a period T (ZOH): x_{k+1} = (Φ + Γ K) x_k,  Φ = e^{AT},  Γ = ∫₀ᵀ e^{As} ds B,
//                                 from exp([[A, B], [0, 0]] T) = [[Φ, Γ], [0, I]] (Van Loan).
//
// The controller is named the cause when it makes the loop grow faster than the model alone:
// a spectral radius ρ(Φ + Γ K) > max(1, ρ(Φ)) per period, or max Re λ(A + B K) above A's, or a
// closed loop stiffer than the fixed step's stability limit (sim/stability.hpp) where A is not.
// Models whose q is a vector space (n_q = n) and without closed loops; others get no verdict.
#pragma once
#include <string>

#include "sim/integrator.hpp"

namespace femdyn {

struct ControlledLoop {
  Status status;                  // failed: no verdict (the reason)
  double plant_stiffest = 0;      // max |λ(A)| (1/s)
  double stiffest = 0;            // max |λ(A + B K)| (1/s)
  double plant_growth = 0;        // max Re λ(A) (1/s)
  double growth = 0;              // max Re λ(A + B K) (1/s)
  double plant_radius = 0;        // held: ρ(Φ)
  double radius = 0;              // held: ρ(Φ + Γ K)
  double stable_period = 0;       // held: a period T' < T with ρ ≤ 1 + 1e-6 (0: none to 1e-9 T)
  double closed_stable_step = 0;  // the fixed step's limit on A + B K (0: adaptive or none)
  double plant_stable_step = 0;   // the same on A
  double dt = 0;                  // the fixed step (0: adaptive)
};

// K = ∂u/∂(q, q̇) at (t, q, v), central differences with steps 1e-6 max(1, |y_i|).
MatX controller_gain(const Model& model, const Control& u, double t, const VecX& q, const VecX& v);

// The loop at (q, v, τ) under the gain K; `period` T of the hold (held), the integrator and its
// fixed step dt (0: adaptive).
ControlledLoop controlled_loop(const Model& model, const VecX& q, const VecX& v, const VecX& tau,
                               const MatX& K, double period, bool held, IntegratorKind kind,
                               double dt);

// A clause naming the controller as the cause with the numbers above, or "" when the loop at the
// start does not implicate it (or no verdict could be made).
std::string controller_cause(const ControlledLoop& loop, double period, bool held);

// controller_gain, controlled_loop and controller_cause at a run's start; "" on any failure
// (the controller's own exception included: the report goes on without the clause).
std::string controller_divergence(const Model& model, const Control& u, double t, const VecX& q,
                                  const VecX& v, double period, bool held, IntegratorKind kind,
                                  double dt);

}  // namespace femdyn
