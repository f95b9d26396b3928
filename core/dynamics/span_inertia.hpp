// Elements that span bodies (ElementEntry::spans: a node on another body, as the coupler rod of
// a four-bar) on the body-level routes. Such an element uses only its nodes' translations x_l
// (world axes) with a constant mass m_e (blocks M_lj, 3 × 3), so its kinetic energy is
//   T_e = ½ Σ_lj ẋ_lᵀ M_lj ẋ_j,
// and by Lagrange, with J_l = ∂x_l/∂q (3 × n; column c the velocity v_c + ω_c × x_l of the
// rate's world column S_c = (ω_c, v_c) at x_l, on the rates of the node's path) and
// ẍ_j = J_j q̈ + J̇_j q̇, its share of the equations is
//   M^s += Σ_lj J_lᵀ M_lj J_j,
//   h   += Σ_l J_lᵀ Σ_j M_lj J̇_j q̇             (ẍ_j at q̈ = 0, no gravity),
//   τ   += Σ_l J_lᵀ Σ_j M_lj (ẍ_j − g)         (its weight M g, as F_constant holds it for Q),
//   T   += ½ Σ_lj ẋ_lᵀ M_lj ẋ_j.
// The rest of the tree keeps its composite inertias and Newton–Euler. The node-level routes
// (Tᵀ M T) compute the same numbers element by element; tests/test_routes.cpp compares them.
// Used where Model::spans_on_bodies (choose_routes, compile/routes.cpp).
#pragma once
#include <string>
#include <vector>

#include "core/model/spanning_mass.hpp"

namespace femdyn {

struct Model;
struct Workspace;

// "" if every spanning element of `model` uses only its nodes' translations and has no velocity
// force (the form above), else why not.
std::string span_inertia_unsupported(const Model& model);

// The spanning masses of `model`'s spanning elements (call where span_inertia_unsupported is "").
std::vector<SpanningMass> spanning_masses(const Model& model);

// ws.Ms += Σ_lj J_lᵀ M_lj J_j at the body poses and joint columns (ws.subspace) in ws.
void add_span_mass(const Model& model, Workspace& ws);

// y += Σ_l J_lᵀ Σ_j M_lj ẍ_j, ẍ from the body motions the Newton–Euler pass left in
// ws.articulated (V, a: with q̈ and −g for τ, without for h).
void add_span_forces(const Model& model, const Workspace& ws, VecX& y);

// ½ Σ_lj ẋ_lᵀ M_lj ẋ_j at the body velocities propagate left in ws.body.
double span_kinetic_energy(const Model& model, const Workspace& ws);

}  // namespace femdyn
