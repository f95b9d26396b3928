// The mechanism as a whole: its centre of mass, its momentum and the centroidal momentum
// matrix, and the generalized Jacobian of a free-floating tree (docs/notation.md#momentum).
//
// Every element form counts, rods that span two bodies included, because everything is read
// off each element's own mass m_e on its own nodes y_l = (x y z, rx ry rz) — not off the
// system's M on u, which leaves out what never moves (a node at rest; a rotation rate that stays
// 0 about a hinge while a full inertia tensor couples it to the others still carries momentum).
// (The origin below is the reference point of the body places, Workspace::origin; c is handed out
// as a world position.)
// A rigid twist ξ = (v₀, ω) of the whole mechanism about the world origin moves node l by
//   ẏ_l = G_l ξ,   G_l = [[1, −[x_l]×], [0, R_eᵀ]]   (R_e: the element's body's rotation),
// so the mechanism locked rigid has the inertia I_O = Σ_e Σ_l,j G_lᵀ m_e[l, j] G_j
// = [[m 1, −[m c]×], [[m c]×, I_O]], and the spatial momentum about the origin is
//   h_O = Σ_e Σ_l,j G_lᵀ m_e[l, j] ẏ_j = A_O v      (linear rows P, then angular L_O)
// with ẏ_j = (v_b + ω_b × r_j, R_eᵀ ω_e) = Y_j v from the bodies' Jacobians. Its rate at v̇ = 0
// (the bias) is
//   Ȧ_O v = Σ G_lᵀ m_e[l, j] ÿ_j(v̇ = 0) + Ġ_lᵀ f_l,   f_l = Σ_j m_e[l, j] ẏ_j,
//   Ġ_lᵀ f = (0, ẋ_l × f_t + ω_e × R_e f_r).
// The centroidal forms shift the moment to c (world axes, Pinocchio's hg/Ag):
//   h_G = (P, L_O − c × P),   A_G = [A_lin ; A_ang − [c]× A_lin],   bias_G = (Ṗ_b, L̇_b − c × Ṗ_b)
// and the centre of mass moves with ċ = P / m: J_c = A_lin / m, c̈ at v̇ = 0 is Ṗ_b / m.
#pragma once
#include <vector>

#include "core/kinematics/frames.hpp"

namespace femdyn {

struct MomentumKinematics {
  double mass = 0;
  Vec3 com = Vec3::Zero();           // c, world
  Mat3 inertia_com = Mat3::Zero();   // the locked mechanism's inertia about c, world axes
  MatX Jcom;                         // 3 × n: ċ = J_c v
  Vec3 com_velocity = Vec3::Zero();  // ċ
  Vec3 com_bias = Vec3::Zero();      // J̇_c v: c̈ at v̇ = 0
  Vec6 momentum = Vec6::Zero();      // h_G = (P, L_G): linear, then angular about c
  MatX A;                            // A_G, 6 × n: h_G = A_G v
  Vec6 bias = Vec6::Zero();          // Ȧ_G v: ḣ_G at v̇ = 0
  // Buffers, sized on first use.
  std::vector<MatX> element_mass;  // m_e of each element of `masses_of`, on first use
  const Model* masses_of = nullptr;
  std::vector<Eigen::Matrix<double, 6, 3>> Wv, Ww;  // per body: A_O's weights on Jv_b, Jω_b
};

// From the body states, Jacobians and T'[v,v] of the last
// propagate(model, ws, q, v, {.jacobian = true, .bias = true}).
void momentum_kinematics(const Model& model, const Workspace& ws, MomentumKinematics& out);
// The same at (q, v), after its own propagate.
void momentum_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v,
                         MomentumKinematics& out);

// Umetani and Yoshida's generalized Jacobian of a free-floating mechanism. With no external
// force the momentum is constant, A_O,b v_b + A_O,m v_m = h_O (b: the free base's 6 rates, m:
// the others), so the base follows the arm, v_b = A_b⁻¹ (h_O − A_m v_m), and a frame moves with
//   J v = J* v_m + J_b A_b⁻¹ h_O,     J* = J_m − J_b A_b⁻¹ A_m.
// (The same with A_G, h_G: the shift from O to c multiplies A_b, A_m and h_O alike.)
struct GeneralizedJacobian {
  MatX J;                     // J*, 6 × (n − 6), in the frame's axes; columns: `rates`
  std::vector<int> rates;     // the indices in v of J*'s columns (every rate but the base's)
  Vec6 drift = Vec6::Zero();  // J_b A_b⁻¹ h_O at the current momentum (zero when h_O = 0)
  MatX A_m;                   // buffer: A's columns of `rates`
};

// The index in v of the base's first rate: the free joint at the root of a mechanism that is
// one tree on it. Throws ModelError otherwise (a fixed base, several trees, several free joints).
int floating_base_rate(const Model& model);

// J* of a frame from its kinematics and the momentum at the same state (frame_kinematics and
// momentum_kinematics after one propagate). Throws ModelError unless the model is one tree on a
// free joint, StateError if A_b is singular (a massless mechanism).
void generalized_jacobian(const Model& model, const FrameKinematics& frame,
                          const MomentumKinematics& momentum, GeneralizedJacobian& out);

}  // namespace femdyn
