// Forward dynamics by the articulated-body recursion over the element-assembled body inertias
// (Featherstone's articulated-body algorithm, "Rigid Body Dynamics Algorithms" ch. 7, written in
// world axes about the world origin so that no transform is needed between bodies).
//
// When the body-level form is exact (Model::condensable) the kinetic energy of the elements is
// Σ_b ½ V_bᵀ Λ_b V_b, so the system equations M^s q̈ + h = Q are those of rigid bodies with the
// spatial inertias Λ_b = Σ_e X_eᵀ m_e X_e, and the elements' velocity forces (ω × J ω of their
// rotary inertias, the Element contract) are the rotary part of V ×* Λ V. With I_b = Λ_b^O
// (core/spatial/spatial.hpp), S_b the joint's motion subspace (6 × nv, core/joints/kernel.hpp), θ̇_b
// its rates and τ_b its forces (τ, plus the spring and damper of a joint of one rate), over the
// bodies in tree order:
//   1. root to leaves:  V_b = V_p + S_b θ̇_b,   c_b = Ṡ_b θ̇_b  (the kernel's c_J; V_b × S_b θ̇_b
//                                                              for one rate),
//                       p_b = V_b ×* I_b V_b − f_b     (f_b: point loads and body torques;
//                                                      gravity is the base acceleration −g,
//                                                      core/dynamics/body_loads.hpp)
//   2. leaves to root:  U_b = I^A_b S_b (6 × nv),  D_b = S_bᵀ U_b (nv × nv),
//                       u_b = τ_b − S_bᵀ p^A_b,
//                       I^A_p += I^A_b − U_b D_b⁻¹ U_bᵀ,
//                       p^A_p += p^A_b + (I^A_b − U_b D_b⁻¹ U_bᵀ) c_b + U_b D_b⁻¹ u_b
//      (a fixed joint passes I^A_b and p^A_b on whole)
//   3. root to leaves:  a'_b = a_p + c_b (a_0 = (0, −g)),
//                       θ̈_b = D_b⁻¹ (u_b − U_bᵀ a'_b),  a_b = a'_b + S_b θ̈_b
// For one rate D_b is the scalar d_b = S_bᵀ I^A_b S_b and the steps are written with it (the
// common case, kept inline). For nv > 1 (universal 2, planar and spherical 3, free 6) D_b is
// factorised per joint at its fixed size (no allocation) as D_b = W Δ Wᵀ, W unit upper
// triangular: the joint's last rate is eliminated first, as the tree LTDL of M^s eliminates it
// (the rates of a joint form a chain, the last one furthest from the root), so the pivots Δ_k
// are the Cholesky route's. O(bodies + N_u), no matrix of size n. Used when
// Model::dynamics_route is Articulated: the body-level form is exact and there is no coupling
// (C = I, θ0 = 0). A coupled model has coordinates that drive several joints, which the
// recursion cannot eliminate one joint at a time; it goes through M^s = Cᵀ M_θ C and a Cholesky
// factorisation instead, which is exact.
//
// Regularity is checked as the Cholesky route checks it, rate by rate: M^s(j, j) = S_jᵀ I^c_b S_j
// (I^c the composite inertia, S_j the column of rate j) must be a non-negligible part of the
// largest diagonal, and the pivot of rate j (d_b, or Δ_k of D_b's factorisation) a
// non-negligible part of M^s(j, j), the diagonal of M^s's block for the joint.
#pragma once
#include "core/workspace/status.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

// q̈ into ws.qdd (and θ, θ̇, the body poses and ω into ws as propagate leaves them). Requires
// Model::dynamics_route == Articulated. ws.Ms, ws.h, ws.Q are not formed.
Status articulated_forward_dynamics(const Model& model, Workspace& ws, const VecX& q,
                                    const VecX& qd, const VecX& tau);

// x ← (M^s)⁻¹ x in O(bodies), M^s never formed: steps 2 and 3 of the recursion at zero velocity
// and no gravity, with x as the joint forces, on the factorisation (U, d; K, D⁻¹ for a block)
// that the last articulated_forward_dynamics left in ws at its q (Featherstone, "Rigid Body
// Dynamics Algorithms" §7.3: the articulated-body algorithm as a factorisation of M⁻¹). Leaves
// ws.qdd and the body states alone; no allocation.
void articulated_solve(const Model& model, Workspace& ws, VecX& x);

}  // namespace femdyn
