// The constraints' kinematics at a state (core/model/loop_constraint.hpp for the forms): the
// residual Φ(q), the Jacobian Φ_q on the rates v (Φ̇ = Φ_q v) and the bias Φ̇_q v, the part of
// Φ̈ = Φ_q q̈ + Φ̇_q v at q̈ = 0. With d = p_A − p_B, ḋ, its bias d̈₀ = a_A − a_B, Jd = Jv_A − Jv_B,
// and for a row along an axis g = R_B e fixed in B (ġ = ω_B × g):
//   ball          Jd;                              bias d̈₀
//   along g       gᵀ (Jd + [d]× Jω_B);             bias gᵀ d̈₀ + 2 (ω_B × g)ᵀ ḋ
//                                                        + (α_B × g + ω_B × (ω_B × g))ᵀ d
//   weld angles   Jω_A − Jω_B;                     bias α_A − α_B
//   distance      êᵀ Jd;                           bias êᵀ d̈₀ + (|ḋ|² − (êᵀ ḋ)²) / l
//   gear          (e_j − Σ r_i e_i)ᵀ C (θ̇ = C v);  bias 0
#pragma once
#include "core/kinematics/frames.hpp"

namespace femdyn {

struct ConstraintKinematics {
  explicit ConstraintKinematics(const Model& model);
  VecX phi;               // Φ (m)
  MatX J;                 // Φ_q (m × n)
  VecX bias;              // Φ̇_q v (m)
  AttachmentMotion A, B;  // buffers
};

// Φ, Φ_q and Φ̇_q v from the body states and Jacobians of the last
// propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false}).
void constraint_kinematics(const Model& model, const Workspace& ws, ConstraintKinematics& out);
// The same with each attachment's Jacobian formed from the path of its body to the root over
// the rates' spatial columns that articulated_forward_dynamics left in ws (C = I;
// core/dynamics/articulated.hpp), and its motion from the body states of the last propagate with
// the bias: O(n + depth) per attachment, no body Jacobians (which cost O(Σ depth) to form).
void constraint_kinematics_by_paths(const Model& model, const Workspace& ws,
                                    ConstraintKinematics& out);
// The same as the first at (q, v), after its own propagate.
void constraint_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v,
                           ConstraintKinematics& out);

// The constraint and its row that row `i` of Φ belongs to, e.g. "close_E[1]".
std::string constraint_row_name(const Model& model, int i);

}  // namespace femdyn
