// The equations of a model with a nonlinear coupling level θ = g(q), chained from those of its
// tree (Model::tree, every joint a coordinate) at θ = g(q), θ̇ = G q̇ (docs/design.md):
//   M^s = Gᵀ M_θ G,   h = Gᵀ (h_θ + M_θ γ),   Q = Gᵀ Q_θ + τ,   τ = Gᵀ τ_θ(θ̈ = G q̈ + γ)
//   T = T_θ G,   T'[x, y] = T'_θ[G x, G y] + T_θ g''[x, y]
//   D_abc = Σ_i G_ia (Σ_jk D^θ_ijk G_jb G_kc + Σ_l M_θ,il H_lbc)
// The route (Model::routes, core/model/routes.hpp) of every function of core/dynamics/equations.hpp
// and of propagate_bilinear for a model with Model::coupling_level; linear couplings never come
// here. A state where a law is not defined (a linkage that cannot assemble) throws StateError from
// the void functions and is a failed Status from forward_dynamics.
#pragma once
#include <vector>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn::chain {

void evaluate(const Model& m, Workspace& ws, const VecX& q, const VecX& qd, const VecX& tau);
void mass_matrix(const Model& m, Workspace& ws, const VecX& q);
void evaluate_bias(const Model& m, Workspace& ws, const VecX& q, const VecX& qd);
// The same by the tree's Newton–Euler at θ̈ = γ, where the tree has the body-level force route.
void evaluate_bias_by_bodies(const Model& m, Workspace& ws, const VecX& q, const VecX& qd);
Status forward_dynamics(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau);
// The same in one pair of sweeps over the tree's bodies with θ̈ = γ as their bias acceleration
// (core/dynamics/coupled_dynamics.hpp), where the tree has the body-level routes
// (Model::force_route == Bodies, Model::mass_route == Composite).
Status forward_dynamics_by_bodies(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                                  const VecX& tau);
void inverse_dynamics(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                      const VecX& qdd);
void propagate_bilinear(const Model& m, Workspace& ws, const VecX& q, const VecX& x, const VecX& y,
                        KinematicsRequest request);
std::vector<MatX> transform_hessian(const Model& m, Workspace& ws, const VecX& q);
std::vector<MatX> third_order_tensor(const Model& m, Workspace& ws, const VecX& q);
Energy energy(const Model& m, Workspace& ws, const VecX& q, const VecX& qd);
void joint_state(const Model& m, Workspace& ws, const VecX& q, const VecX& qd);

}  // namespace femdyn::chain
