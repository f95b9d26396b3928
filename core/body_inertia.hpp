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
// as for every physical element). compile() checks both (Model::condensable) and uses the form
// where it takes fewer operations than the dense product (Model::condensed).
#pragma once
#include "core/model.hpp"

namespace femdyn {

void condense_body_inertia(Model& model);

}  // namespace femdyn
