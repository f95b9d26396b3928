// The mechanism as a whole: its centre of mass, its momentum and the centroidal momentum
// matrix, and the generalized Jacobian of a free-floating tree (docs/notation.md#momentum).
//
// Every element form counts, rods that span two bodies included, because everything is read
// off the system's lumped mass M (constant in u, core/model.hpp) through the rigid-motion map
// G (N_u × 6): the u̇ that a rigid twist ξ = (v₀, ω) of the whole mechanism about the world
// origin would give,
//   a translation DOF (node at x, axis k):  u̇_i = e_kᵀ (v₀ + ω × x)
//   a rotation DOF (body b, axis k):        u̇_i = (R_b e_k)ᵀ ω.
// The kinetic energy is ½ u̇ᵀ M u̇, so the spatial momentum about the origin is the vector h_O
// with ξᵀ h_O = u̇(ξ)ᵀ M u̇ for every ξ:
//   h_O = Gᵀ M u̇ = (MG)ᵀ T v = A_O v          (linear rows P, then angular L_O)
// The mechanism locked rigid has the inertia Σ_e G_eᵀ m_e G_e = [[m 1, −[m c]×], [[m c]×, I_O]],
// summed over the elements' own DOFs (G_e: the same map on each node's x y z and its body's
// rx ry rz): u leaves out what never moves, but a node that never moves still has mass.
// and, M being constant, its rate at v̇ = 0 (the bias) is
//   Ȧ_O v = (MG)ᵀ T'[v,v] + Ġᵀ M u̇,   Ġᵀ f = (0, Σ_trans ẋ × e_k f_i + Σ_rot (ω_b × R_b e_k) f_i).
// The centroidal forms shift the moment to c (world axes, Pinocchio's hg/Ag):
//   h_G = (P, L_O − c × P),   A_G = [A_lin ; A_ang − [c]× A_lin],   bias_G = (Ṗ_b, L̇_b − c × Ṗ_b)
// and the centre of mass moves with ċ = P / m: J_c = A_lin / m, c̈ at v̇ = 0 is Ṗ_b / m.
#pragma once
#include <vector>

#include "core/frames.hpp"

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
  Eigen::Matrix<double, Eigen::Dynamic, 6> G, MG;  // G and M G, N_u × 6
  VecX Mu;                                         // M u̇
  std::vector<MatX> element_mass;  // m_e of each element of `masses_of`, on first use
  const Model* masses_of = nullptr;
  std::vector<Eigen::Matrix<double, 6, 3>> Wv, Ww;  // per body: (MG)ᵀ gathered on Jv_b, Jω_b
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

// J* of `frame` at the last propagate (as momentum_kinematics); `frame_out` and `momentum` are
// filled on the way. Throws StateError if A_b is singular (a massless mechanism).
void generalized_jacobian(const Model& model, const Workspace& ws, int frame, FrameAxes axes,
                          FrameKinematics& frame_out, MomentumKinematics& momentum,
                          GeneralizedJacobian& out);

}  // namespace femdyn
