#include "core/workspace/workspace.hpp"

#include <algorithm>

namespace femdyn {

Workspace::Workspace(const Model& model) : solver(model) {
  const int n = model.n(), nt = model.n_theta(), N = model.n_u();
  const int nb = static_cast<int>(model.bodies.size());
  theta = VecX::Zero(model.n_theta_q);
  theta_dot = VecX::Zero(nt);
  theta_dot_y = VecX::Zero(nt);
  body.assign(nb, BodyState{});
  // The body Jacobians (3nb x n each) are sized on first use: the condensed route never forms
  // them (a 1000-link chain would need 48 MB for nothing).
  // T (N_u x n) and M T are sized on first use: a model whose M^s is condensed by body never
  // forms them in evaluate(), and at thousands of bodies they are the largest buffers.
  bias = VecX::Zero(N);
  u_dot = VecX::Zero(N);
  nodal = VecX::Zero(N);
  u_acc = VecX::Zero(N);
  composite.assign(nb, RigidInertia{});
  subspace.assign(model.n_theta(), Vec6::Zero());
  if (model.dynamics_route == DynamicsRoute::Articulated || model.force_route == ForceRoute::Bodies)
    articulated.assign(nb, ArticulatedBody{});
  if (model.dynamics_route == DynamicsRoute::Articulated) {
    solve_force.assign(nb, Vec6::Zero());
    solve_acceleration.assign(nb, Vec6::Zero());
  }
  if (model.dynamics_route == DynamicsRoute::Articulated &&
      std::any_of(model.bodies.begin(), model.bodies.end(),
                  [](const Body& b) { return b.joint.nv > 1; }))
    articulated_rate.assign(nt, ArticulatedRate{});
  force.assign(nb, Vec3::Zero());
  moment.assign(nb, Vec3::Zero());
  tau_theta = VecX::Zero(nt);
  for (const ElementEntry& e : model.elements) {
    const auto k = static_cast<Eigen::Index>(e.table_row.size());
    local_x.emplace_back(VecX::Zero(k));
    local_y.emplace_back(VecX::Zero(k));
    local_g.emplace_back(VecX::Zero(k));
  }
  // M^s (n x n) is sized on first use: the articulated route never forms it, and a chain of
  // 10,000 bodies would need 800 MB for it.
  h = Q = qdd = tau = VecX::Zero(n);
  if (model.coupling_level) {
    tree = std::make_unique<Workspace>(*model.tree);
    level = std::make_unique<CouplingLevelState>(*model.coupling_level);
    Ms = MatX::Zero(n, n);
    // Factorised once here: sizes its storage and sets its status (Eigen's LLT(n) leaves the
    // status unset, and copying it is undefined behaviour, which UBSan reports).
    reduced.compute(MatX::Identity(n, n));
  }
}

}  // namespace femdyn
