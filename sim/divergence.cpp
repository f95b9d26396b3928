#include "sim/divergence.hpp"

namespace femdyn {

double potential_reach(const Model& model, const Workspace& ws) {
  // Through a nonlinear coupling level the nodes and loads are the tree's.
  if (model.coupling_level) return potential_reach(*model.tree, *ws.tree);
  // F_constant holds the forces per translation DOF (world axes): gather them per node.
  std::vector<Vec3> force(model.nodes.size(), Vec3::Zero());
  for (int i = 0; i < model.n_u(); ++i) {
    const SystemDof& d = model.dofs[i];
    if (d.kind == DofKind::Translation && model.F_constant[i] != 0)
      force[d.carrier][d.axis] += model.F_constant[i];
  }
  double reach = 0;
  for (std::size_t k = 0; k < force.size(); ++k) {
    if (force[k].isZero(0)) continue;
    const SystemNode& node = model.nodes[k];
    const BodyState& B = ws.body[node.body];
    reach += force[k].norm() * (ws.origin + (B.p + B.R * node.r)).norm();  // (world, as V's x)
  }
  return reach;
}

}  // namespace femdyn
