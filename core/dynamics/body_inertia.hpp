// Body-level condensation of the system mass: M^s = Tᵀ M T evaluated body by body.
//
// Under a rigid motion of body b with twist (ω_b, v_b) (body axes; v_b the velocity of the body
// origin), every local DOF of an element on b moves as u_e = X_e (ω_b, v_b): a node
// translation (world axes) R_b(v_b − [r]× ω_b), a rotation rate (body axes) ω_b. The rows T_e
// of T for the element are therefore X_e J_b, with J_b the body Jacobian, and
//     M^s = Σ_e T_eᵀ m_e T_e = Σ_b J_bᵀ Λ_b J_b,      Λ_b = Σ_{e on b} X_eᵀ m_e X_e   (6 × 6),
// the same matrix with the element sums done once at compile time. J_b is non-zero only on the
// coordinates that move b (its path to the root), so a body costs O(p_b²) with p_b their number,
// instead of O(N_u n²) for the dense product.
//
// Valid when T_e = X_e J_b holds for every element DOF, i.e. when the correlation table is the
// automatic one (an explicit table may give a DOF another body's motion, or leave out one that
// moves), and when Λ_b does not depend on the body's orientation (translation inertia isotropic,
// as for every physical element). compile() checks both (Model::condensable) and chooses the
// routes (choose_routes, compile/routes.hpp: Model::mass_route, Model::dynamics_route).
//
// At run time the same Λ_b give M^s by composite inertias (the composite-rigid-body recursion,
// Featherstone ch. 6), O(bodies · depth) instead of O(Σ p_b²):
//   Λ_b^O = Xᵀ Λ_b^w X,  X = [[I, 0], [−[p_b]×, I]]     (world axes, twist about the origin)
//   I^c_b = Λ_b^O + Σ_{children c} I^c_c                (leaves to root)
//   M_θ(i, k) = S_kᵀ I^c_{b(i)} S_i   for each joint k on the path of the body b(i) of joint i,
//   S = (s, p_b × s) revolute, (0, s) prismatic          (s the world axis, p_b the joint origin)
//   M^s = Cᵀ M_θ C   (M_θ itself when C = I).
#pragma once
#include "core/model/model.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

void condense_body_inertia(Model& model);

// The sum of the body's elements' mass properties (body frame); an element that spans bodies
// (a rod) moves with no single body and is left out.
MassProperties body_mass_properties(const Model& model, int body);
// The same for every body at once, in O(elements).
std::vector<MassProperties> body_mass_properties(const Model& model);

// ws.composite: the composite inertias I^c_b (world axes, about the origin) from the body poses.
void composite_inertias(const Model& model, Workspace& ws);

// ws.Ms from the body poses of the last propagate (no Jacobians needed): composite inertias,
// motion subspaces, then whole_mass_from_composites.
void composite_mass(const Model& model, Workspace& ws);

// The whole symmetric ws.Ms from ws.composite and ws.subspace: mass_from_composites mirrored,
// plus the spanning elements' terms (core/dynamics/span_inertia.hpp; sized on first use).
void whole_mass_from_composites(const Model& model, Workspace& ws);

// ws.Ms from ws.composite and ws.subspace: the upper triangle without couplings (mirror it),
// the whole of Cᵀ M_θ C with them.
void mass_from_composites(const Model& model, Workspace& ws);

}  // namespace femdyn
