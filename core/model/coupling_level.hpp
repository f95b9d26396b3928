// The nonlinear coupling level θ = g(q) (docs/design.md#nonlinear-couplings): each coupled joint
// follows a law of the joints it follows, θ_t = f_t(θ_s1, θ_s2, …), resolved in dependency order.
// Its derivatives chain forward by the product rule:
//   G_t = ∂θ_t/∂q = Σ_k f_k G_sk                            (θ̇ = G q̇)
//   γ_t = Σ_k f_k γ_sk + Σ_kl f_kl θ̇_sk θ̇'_sl              (θ̈ = G q̈ + γ, γ = g''[q̇, q̇'])
//   H_t = ∂²θ_t/∂q² = Σ_k f_k H_sk + Σ_kl f_kl G_skᵀ G_sl    (on request: D and T')
// A model with such a level carries its tree (every joint a coordinate, Model::tree); the
// equations are formed on the tree at (θ, θ̇) and reduced (core/dynamics/coupling_chain.hpp).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/model/coupling_function.hpp"
#include "core/spatial/math.hpp"

namespace femdyn {

struct CoupledJoint {
  int theta = -1;            // the θ it sets
  std::vector<int> sources;  // the θ it follows, each resolved before it
  std::shared_ptr<const CouplingFunction> law;
  std::string name, where;  // the joint, and the coupling's place in the file
};

struct CouplingLevel {
  int n = 0, n_theta = 0, n_theta_q = 0;  // rates v, joint rates θ̇, joint coordinates θ
  std::vector<int> coordinate_theta;      // v index -> θ̇ index
  std::vector<int> configuration_theta;   // q index (n_q) -> θ index: the coordinates' own joints
  std::vector<int> theta_q;  // θ̇ index -> its θ index on a flat joint, -1 on a quaternion joint
  std::vector<CoupledJoint> coupled;  // in dependency order
  int largest_arity = 0;
};

// One evaluation's results and scratch (held by the Workspace: no allocation per call).
struct CouplingLevelState {
  explicit CouplingLevelState(const CouplingLevel& level);
  VecX theta, theta_dot, theta_dot_y, gamma;  // θ (n_θq), G x, G y, g''[x, y] (nθ)
  MatX G;                                     // ∂θ/∂q, nθ × n
  // G's structural non-zeros row by row: row t may be non-zero only in the columns
  // g_col[g_begin[t] .. g_begin[t + 1]), the coordinates its joint follows (directly or through
  // other laws). The reductions through G (core/dynamics/coupling_chain.cpp) visit only these.
  std::vector<int> g_begin, g_col;
  std::vector<MatX> H;             // ∂²θ_t/∂q², sized on the first request
  std::vector<double> x, df, d2f;  // one law's arguments and derivatives
  VecX f_theta, theta_ddot;        // θ-level force and acceleration buffers
  int failed = -1;                 // index into coupled[] where a law is undefined
};

// θ = g(q) (q of n_q entries; laws act on joints of one coordinate), G, θ̇ = G x, θ̇_y = G y, γ =
// g''[x, y] (and H with `hessian`). False when a law is not defined at this q (s.failed names it).
bool evaluate_level(const CouplingLevel& level, const VecX& q, const VecX& x, const VecX& y,
                    CouplingLevelState& s, bool hessian = false);

}  // namespace femdyn
