// h and τ by the recursive Newton–Euler algorithm over the element-assembled body inertias
// (Featherstone, "Rigid Body Dynamics Algorithms" ch. 5, in world axes about the world origin,
// core/spatial/spatial.hpp): the body-level form of the node-level sweeps
//   h = Tᵀ (M T'[q̇,q̇] + g(u̇,u̇)),   τ = Tᵀ (M (T q̈ + T'[q̇,q̇]) + g(u̇,u̇) − F) − Cᵀ(spring + damper).
// Exact under the same conditions as the articulated route (core/dynamics/articulated.hpp): the
// body-level form holds and the elements' velocity forces are their gyroscopic terms. Couplings are
// linear, so θ̇ = C q̇, θ̈ = C q̈ and the joint forces map back by Cᵀ. With I_b = Λ_b^O, S_b the motion
// subspace, over the bodies in tree order:
//   root to leaves:  V_b = V_p + S_b θ̇_b,   a_b = a_p + S_b θ̈_b + V_b × S_b θ̇_b,
//                    f_b = I_b a_b + V_b ×* I_b V_b − f^ext_b
//   leaves to root:  τ_θ(b) = S_bᵀ f_b,   f_p += f_b
// O(bodies), with gravity as a base acceleration a_0 = −g and f^ext the point loads and body
// torques (core/dynamics/body_loads.hpp).
#pragma once
#include "core/workspace/workspace.hpp"

namespace femdyn {

// y = Cᵀ τ_θ for the motion (q, q̇, q̈) (q̈ = nullptr: q̈ = 0), minus the external forces when
// `with_external` (F and body torques, not springs or dampers). Leaves θ, θ̇, the body poses and
// ω in ws. Requires Model::force_route == Bodies.
void newton_euler(const Model& model, Workspace& ws, const VecX& q, const VecX& qd, const VecX* qdd,
                  bool with_external, VecX& y);

}  // namespace femdyn
