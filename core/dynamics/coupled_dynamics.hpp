// Forward dynamics of a coupled model on the body-level routes, in one pair of sweeps that serves
// both sides of M^s q̈ = Q − h (world axes about the world origin, core/spatial/spatial.hpp). With
// I_b = Λ_b^O formed once per body and the joints' accelerations θ̈ = C q̈ + γ (γ = 0 for a linear
// coupling θ = C q + θ0, γ = g''[q̇, q̇] for a coupling law θ = g(q),
// core/dynamics/coupling_chain.hpp):
//   root to leaves:  V_b = V_p + S_b θ̇_b,   a_b = a_p + V_b × S_b θ̇_b + S_b γ_b   (a_0 = (0, −g)),
//                    f_b = I_b a_b + V_b ×* I_b V_b − f^ext_b           (Newton–Euler at q̈ = 0)
//   leaves to root:  τ_θ(b) = S_bᵀ f_b,   f_p += f_b,   I^c_p += I^c_b   (composite inertias)
// so that τ_θ is the joints' inverse dynamics at θ̈ = γ (less their springs and dampers, plus
// their rotors' I_a γ), Q − h = τ − Cᵀ τ_θ, and M^s = Cᵀ M_θ C from M_θ(k, i) = S_kᵀ I^c_i S_i
// (core/dynamics/body_inertia.hpp), then a Cholesky factorisation (core/workspace/mass_solver.hpp).
// Why not the articulated recursion: it eliminates one joint at a time, and a coordinate that
// drives several joints cannot be eliminated that way (docs/design.md, "Couplings in forward
// dynamics"). O(bodies · depth) for M^s plus the factorisation.
#pragma once
#include "core/workspace/status.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

// The sweeps above over `model`'s bodies at the poses and joint rates ws.theta_dot already in ws
// (propagate): ws.tau_theta = τ_θ at θ̈ = gamma (nullptr: 0), ws.composite and ws.subspace.
void joint_force_sweeps(const Model& model, Workspace& ws, const VecX* gamma);

// q̈ into ws.qdd, M^s into ws.Ms (factorised in ws.solver); θ, θ̇ and the body poses as
// propagate leaves them. Requires the body-level routes (Model::force_route == Bodies,
// Model::mass_route == Composite) and a linear coupling.
Status coupled_forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                                const VecX& tau);

}  // namespace femdyn
