// The kinematic levels: forward propagation of (value, rate, bias) from q outwards.
//
//   coupling:  θ = C q + θ0,  θ̇ = C q̇                       (no bias: the coupling is linear)
//   tree:      per body, parents first (s = joint axis in world, r = p_b − p_parent):
//     revolute   R_b = R_p R_pj Rot(a, θ),  ω_b = ω_p + s θ̇,  v_b = v_p + ω_p × r
//                α_b = α_p + ω_p × s θ̇,      a_b = a_p + α_p × r + ω_p × (ω_p × r)
//     prismatic  p_b = o + s θ,  ω_b = ω_p,  v_b = v_p + ω_p × r + s θ̇
//                α_b = α_p,     a_b = a_p + α_p × r + ω_p × (ω_p × r) + 2 ω_p × s θ̇
//     Jacobians  Jω_b = Jω_p + s C_j (revolute),  Jv_b = Jv_p − [r]× Jω_p + s C_j (prismatic)
//   nodes:     node translation (r_w = R_b r):  T_i = e_kᵀ (Jv_b − [r_w]× Jω_b),
//                 b_i = e_kᵀ (a_b + α_b × r_w + ω_b × (ω_b × r_w))
//              body rotation (body axes):      T_i = (R_b e_k)ᵀ Jω_b,  b_i = (R_b e_k)ᵀ α_b
//              (d/dt Rᵀω = Rᵀω̇ − Rᵀ[ω]×ω = Rᵀω̇, so the rotation level adds no bias)
// The product T = T^nodes T^tree C is formed row by row; b = T'[q̇,q̇] costs one sweep.
#pragma once
#include "core/workspace.hpp"

namespace femdyn {

struct KinematicsRequest {
  bool jacobian = true;  // T (needed for M^s, Q)
  bool bias = true;      // T'[q̇,q̇] and u̇ (needed for h)
};

// Fills ws.theta, ws.theta_dot, ws.body, and per request ws.T / ws.bias / ws.u_dot.
void propagate(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
               KinematicsRequest request);

}  // namespace femdyn
