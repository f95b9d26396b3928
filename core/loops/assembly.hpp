// Putting a closed mechanism together (docs/loops.md#assembly):
//
//   assemble          Newton on Φ(q) = 0 from a guess: the least-norm step Δ = −Φ_q⁺ Φ (a
//                     complete orthogonal decomposition, so that redundant and rank-deficient
//                     Φ_q are fine), q ← q ⊕ Δ, halved while |Φ| does not fall. Held rates keep
//                     their values (their columns of Φ_q are left out of the step).
//   project_velocity  v ← v − M⁻¹ Φ_qᵀ S⁺ Φ_q v: the velocity nearest v in the kinetic-energy
//                     metric with Φ_q v = 0 (an impulse through the constraints).
//
// Both are also the drift projection after an integration step (sim/motion.hpp).
#pragma once
#include <string>
#include <vector>

#include "core/loops/constrained_dynamics.hpp"

namespace femdyn {

struct AssemblyOptions {
  double tolerance = 1e-12;  // on |Φ|∞ (m, rad)
  int max_iterations = 50;
  std::vector<int> held;  // rates (v indices) the step leaves alone
  bool rank = true;       // find Φ_q's rank at the end (a projection after a step does not)
};

struct AssemblyReport {
  Status status;
  int iterations = 0;
  double residual = 0;  // |Φ|∞ at the end
  std::string worst;    // the constraint row where it is largest
  int rank = 0;         // of Φ_q at the end (−1 when not asked)
  int redundant = 0;    // m − rank: equations that repeat others
};

AssemblyReport assemble(const Model& model, Workspace& ws, ConstraintKinematics& k, VecX& q,
                        const AssemblyOptions& options = {});

Status project_velocity(const Model& model, Workspace& ws, LoopWorkspace& lws, const VecX& q,
                        VecX& v);

// The start of a run: q assembled, then v projected (own workspaces). `velocity_change` is
// |Δv|∞ of the projection.
struct StateAssembly {
  AssemblyReport assembly;
  double velocity_change = 0;
};
StateAssembly assemble_state(const Model& model, VecX& q, VecX& v,
                             const AssemblyOptions& options = {});

}  // namespace femdyn
