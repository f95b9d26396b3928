// System equations of motion at a state (paper §III, corrected — docs/design.md):
//
//   M^s q̈ + h = Q,     M^s = Tᵀ M T,
//   h = D[q̇,q̇] = Tᵀ (M T'[q̇,q̇] + g(u̇,u̇)),        g: element velocity (gyroscopic) forces
//   Q = Tᵀ F + Cᵀ (−k (θ − θ_rest) − c θ̇) + τ,      F: gravity, loads; τ: actuation on q
//
// Only what the state needs is computed: no h at rest (q̇ = 0), no T at all for h alone.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "core/workspace/status.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

// Every function below checks the sizes of its arguments (core/model/arguments.hpp): q has n_q
// entries, q̇ and q̈ have n, τ has n or none (no actuation); a wrong size throws ArgumentError naming
// the function and the argument.
//
// Fills ws.Ms, ws.h, ws.Q for the state (q, q̇, τ).
void evaluate(const Model& model, Workspace& ws, const VecX& q, const VecX& qd, const VecX& tau);

// M^s alone into ws.Ms (the body poses, or T, and nothing of h or Q).
void mass_matrix(const Model& model, Workspace& ws, const VecX& q);

// Velocity terms alone, h(q, q̇) (one kinematic sweep, T not formed).
void evaluate_bias(const Model& model, Workspace& ws, const VecX& q, const VecX& qd);

// q̈ = (M^s)⁻¹ (Q − h) into ws.qdd, by the model's route (Model::dynamics_route): the
// articulated-body recursion (core/dynamics/articulated.hpp), which forms neither M^s nor h nor Q,
// or a Cholesky factorisation of M^s (with Q − h from one Newton–Euler pass where the body level is
// exact, else from evaluate()). Call evaluate() for M^s, h and Q. Fails on a singular or indefinite
// M^s and on a q̈ that is not finite (naming the coordinate). The mechanism's q̈: a model with closed
// loops is refused (ArgumentError, one line), since its q̈ is the constrained one
// (mechanism_forward_dynamics, core/loops/constrained_dynamics.hpp).
Status forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau);
// The same for the spanning tree, the model's loops ignored: the unconstrained q̈₀ the
// constrained equations start from, or a tree-level comparison.
Status tree_forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                             const VecX& tau);

// A q̈ that overflowed as a failure naming the coordinate (never a NaN handed on), else ok.
Status finite_accelerations(const Model& model, const VecX& qdd);

// τ such that M^s q̈ + h = Q(τ), into ws.tau.
void inverse_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                      const VecX& qdd);

// D_abc with h_a = Σ_bc D_abc q̇_b q̇_c:  D_abc = Σ_i T_ia (M T'_{·bc} + G_{·bc})_i,
// T'_{·bc} = ∂T_{·b}/∂q_c, G_{·bc} = g(T e_b, T e_c). D[a](b, c). On request.
// With this D, C_ab = Σ_c D_abc q̇_c = Tᵀ M Ṫ + Tᵀ G[·, q̇] makes Ṁ^s − 2C skew, and the part
// of D symmetric in (b, c) is the Christoffel symbols of the first kind of M^s.
std::vector<MatX> third_order_tensor(const Model& model, Workspace& ws, const VecX& q);

// T'_{ibc} = ∂T_ib/∂q_c as N_u matrices of n x n (not symmetric in b, c on rotation rows).
std::vector<MatX> transform_hessian(const Model& model, Workspace& ws, const VecX& q);

// Mechanical energy: kinetic ½ q̇ᵀ M^s q̇; potential of the conservative forces,
// V = −Σ_i F_i x_i (gravity and constant loads, x_i the node positions) + Σ ½ k (θ − θ_rest)².
struct Energy {
  double kinetic = 0, potential = 0;
  double total() const { return kinetic + potential; }
};
Energy energy(const Model& model, Workspace& ws, const VecX& q, const VecX& qd);

// The joint coordinates and rates of the state into ws.theta, ws.theta_dot: θ = C q + θ0,
// θ̇ = C q̇, or through a nonlinear coupling level θ = g(q), θ̇ = G q̇ (throws StateError where a
// law is not defined). For reports and comparisons joint by joint (validation, studies).
void joint_state(const Model& model, Workspace& ws, const VecX& q, const VecX& qd);

// Which route computes what on this model, by name (EquationRoutes::names): M^s, h and τ, the
// tree's q̈, the factorisation of M^s where q̈ goes through one ("" on the articulated route), and
// the closed loops' constrained q̈ ("" without loops). `femdyn info`, `equations --json`, the
// run reports and Python's Model.routes print it.
struct RouteReport {
  std::string mass, force, forward, solver, loops;
  // (key, name) of those that apply: "mass", "force", "forward_dynamics", "solver", "loops".
  std::vector<std::pair<std::string, std::string>> fields() const;
};
RouteReport route_report(const Model& model);

}  // namespace femdyn
