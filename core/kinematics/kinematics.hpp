// The kinematic levels: forward propagation of (value, rate, bias) from q outwards.
//
// The bias is the bilinear form T'[x, y] = Σ_bc (∂T_{·b}/∂q_c) x_b y_c — the derivative of the
// rate T x along y — so that T'[q̇,q̇] = Ṫ q̇ is the acceleration at q̈ = 0. (Rotation rows of u
// are quasi-velocities, so ∂T_ib/∂q_c is not symmetric in b, c there.) With ω(x), ω(y) the
// rates along x and y, s the joint axis in world, r = p_b − p_parent:
//   coupling:  θ = C q + θ0,  θ̇ = C x                       (no bias: the coupling is linear)
//   tree, parents first:
//     revolute   R_b = R_p R_pj Rot(a, θ),  ω_b = ω_p + s θ̇,  v_b = v_p + ω_p × r
//                α_b = α_p + ω_p(y) × s θ̇(x)
//                a_b = a_p + α_p × r + ω_p(x) × (ω_p(y) × r)
//     prismatic  p_b = o + s θ,  ω_b = ω_p,  v_b = v_p + ω_p × r + s θ̇
//                a_b = (as revolute) + ω_p(x) × s θ̇(y) + ω_p(y) × s θ̇(x)
//     Jacobians  Jω_b = Jω_p + s C_j (revolute),  Jv_b = Jv_p − [r]× Jω_p + s C_j (prismatic)
//   nodes:     node translation (r_w = R_b r):  T_i = e_kᵀ (Jv_b − [r_w]× Jω_b),
//                 b_i = e_kᵀ (a_b + α_b × r_w + ω_b(x) × (ω_b(y) × r_w))
//              body rotation (body axes):      T_i = (R_b e_k)ᵀ Jω_b,
//                 b_i = (R_b e_k)ᵀ (α_b + ω_b(x) × ω_b(y))     (d_y Rᵀ = −Rᵀ[ω(y)]×)
// For x = y these are the familiar velocity-product terms (2 ω × s θ̇ for a slider, and the
// rotation level adds no bias). T = T^nodes T^tree C is formed row by row; T'[q̇,q̇] costs one
// sweep.
#pragma once
#include "core/workspace/workspace.hpp"

namespace femdyn {

struct KinematicsRequest {
  bool jacobian = true;  // body Jacobians Jω, Jv, and with `rows` the rows of T
  bool bias = true;      // T'[x, y] and u̇ = T x (needed for h)
  bool rows = true;      // form T itself (not needed when M^s is condensed by body)
};

// Fills ws.theta, ws.theta_dot, ws.body, and per request ws.T / ws.bias / ws.u_dot, with
// the rate x = y = q̇.
void propagate(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
               KinematicsRequest request);

// The same with two rates: ws.bias = T'[x, y], ws.u_dot = T x. By the model's route
// (Model::routes): the levels below, or through a nonlinear coupling level the law chain.
void propagate_bilinear(const Model& model, Workspace& ws, const VecX& q, const VecX& x,
                        const VecX& y, KinematicsRequest request);
// The route of every model without a nonlinear coupling law: θ = C q + θ0, the tree, the nodes.
void propagate_bilinear_levels(const Model& model, Workspace& ws, const VecX& q, const VecX& x,
                               const VecX& y, KinematicsRequest request);

// y = Tᵀ f (+ the generalized force of body torques × torque_scale) without forming T, by the
// principle of virtual work on the tree: each nodal force is gathered into its carrier body's
// wrench (force F_b and moment N_b about the body origin, world frame: a translation DOF of
// node x pushes e_k f_i at x, a rotation DOF turns by f_i about the body axis R_b e_k), the
// wrenches are accumulated from the leaves to the root,
//     F_p += F_b,   N_p += N_b + (p_b − p_p) × F_b,
// and projected on each column of each joint's S (core/joints/kernel.hpp), τ_k = s_ω,kᵀ N_b +
// s_v,kᵀ F_b (revolute: sᵀ N_b, prismatic: sᵀ F_b);
// then y = Cᵀ τ_θ. O(N_u + bodies). Uses the body poses of the last propagate.
void apply_transpose(const Model& model, Workspace& ws, const VecX& f, VecX& y,
                     double torque_scale = 0);

}  // namespace femdyn
