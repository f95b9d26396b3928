// Forward dynamics by the articulated-body recursion over the element-assembled body inertias
// (Featherstone's articulated-body algorithm, "Rigid Body Dynamics Algorithms" ch. 7, written in
// world axes about the world origin so that no transform is needed between bodies).
//
// When the body-level form is exact (Model::condensable) the kinetic energy of the elements is
// Σ_b ½ V_bᵀ Λ_b V_b, so the system equations M^s q̈ + h = Q are those of rigid bodies with the
// spatial inertias Λ_b = Σ_e X_eᵀ m_e X_e, and the elements' velocity forces (ω × J ω of their
// rotary inertias, the Element contract) are the rotary part of V ×* Λ V. With I_b = Λ_b^O
// (core/spatial.hpp), S_b the joint's motion subspace, θ̇_b its rate and τ_b its force
// (τ + spring + damper), over the bodies in tree order:
//   1. root to leaves:  V_b = V_p + S_b θ̇_b,   c_b = V_b × S_b θ̇_b,
//                       p_b = V_b ×* I_b V_b − f_b     (f_b: point loads and body torques;
//                                                      gravity is the base acceleration −g,
//                                                      core/body_loads.hpp)
//   2. leaves to root:  U_b = I^A_b S_b,  d_b = S_bᵀ U_b,  u_b = τ_b − S_bᵀ p^A_b,
//                       I^A_p += I^A_b − U_b U_bᵀ / d_b,
//                       p^A_p += p^A_b + (I^A_b − U_b U_bᵀ / d_b) c_b + U_b u_b / d_b
//      (a fixed joint passes I^A_b and p^A_b on whole)
//   3. root to leaves:  a'_b = a_p + c_b (a_0 = (0, −g)),
//                       θ̈_b = (u_b − U_bᵀ a'_b) / d_b,  a_b = a'_b + S_b θ̈_b
// O(bodies + N_u), no matrix of size n. Used when Model::dynamics_route is Articulated: the
// body-level form is exact and there is no coupling (C = I, θ0 = 0). A coupled model has
// coordinates that drive several joints, which the recursion cannot eliminate one joint at a
// time; it goes through M^s = Cᵀ M_θ C and a Cholesky factorisation instead, which is exact.
//
// Regularity is checked as the Cholesky route checks it: M^s(b, b) = S_bᵀ I^c_b S_b (I^c the
// composite inertia) must be a non-negligible part of the largest diagonal, and the pivot d_b a
// non-negligible part of M^s(b, b).
#pragma once
#include "core/status.hpp"
#include "core/workspace.hpp"

namespace femdyn {

// q̈ into ws.qdd (and θ, θ̇, the body poses and ω into ws as propagate leaves them). Requires
// Model::dynamics_route == Articulated. ws.Ms, ws.h, ws.Q are not formed.
Status articulated_forward_dynamics(const Model& model, Workspace& ws, const VecX& q,
                                    const VecX& qd, const VecX& tau);

}  // namespace femdyn
