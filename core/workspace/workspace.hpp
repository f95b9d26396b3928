// Workspace: everything an evaluation writes. Sized once for a Model, so the algorithms
// (core/kinematics/kinematics.hpp, core/dynamics/equations.hpp) do not allocate per call.
#pragma once
#include <array>
#include <vector>

#include "core/model/attachment.hpp"
#include "core/model/model.hpp"
#include "core/workspace/mass_solver.hpp"

namespace femdyn {

struct BodyState {
  Mat3 R = Mat3::Identity();  // R_WB, body orientation in world
  Vec3 p = Vec3::Zero();      // p_WB − o: body origin in world axes, from the reference point
                              // o = Workspace::origin (world position p_WB = o + p)
  Vec3 w = Vec3::Zero();      // ω, angular velocity (world), along the rate x
  Vec3 w_y = Vec3::Zero();    // ω along the second rate y of the bilinear bias
  Vec3 v = Vec3::Zero();      // velocity of the body origin (world)
  Vec3 alpha = Vec3::Zero();  // bias angular acceleration (q̈ = 0)
  Vec3 a = Vec3::Zero();      // bias acceleration of the body origin (q̈ = 0)
};

// Per body, the body-level recursions' quantities (core/dynamics/articulated.hpp,
// core/dynamics/newton_euler.hpp), spatial vectors in world axes about the world origin
// (core/spatial/spatial.hpp). Newton–Euler keeps its body forces in pA. R_P for body b: its
// parent's orientation, the identity under the world.
inline const Mat3 kWorldRotation = Mat3::Identity();
inline const Mat3& parent_rotation(const Model& m, const std::vector<BodyState>& body, int b) {
  const int p = m.bodies[b].parent;
  return p < 0 ? kWorldRotation : body[p].R;
}

struct ArticulatedBody {
  Mat6 IA = Mat6::Zero();  // articulated inertia I^A
  Vec6 S = Vec6::Zero();   // joint motion subspace
  Vec6 V = Vec6::Zero();   // spatial velocity
  Vec6 c = Vec6::Zero();   // velocity-product acceleration V × S θ̇
  Vec6 pA = Vec6::Zero();  // articulated bias force p^A
  Vec6 U = Vec6::Zero();   // I^A S
  Vec6 a = Vec6::Zero();   // spatial acceleration
  double d = 0, u = 0;     // Sᵀ I^A S, and τ − Sᵀ p^A
  double trace = 0;        // tr(I^c), the composite inertia's trace (a bound for the pivots)
  RigidInertia I;          // the body's own inertia I_b (world axes about the origin)
};

// Per rate of a joint of several rates (nv > 1), the articulated route's block quantities
// (core/dynamics/articulated.hpp); the rate's column of S is in Workspace::subspace.
struct ArticulatedRate {
  Vec6 K = Vec6::Zero();     // its row of D⁻¹ Uᵀ (D = Sᵀ I^A S, U = I^A S)
  Vec6 Dinv = Vec6::Zero();  // its row of D⁻¹ (the joint's nv entries), for articulated_solve
  double Du = 0;             // its entry of D⁻¹ u (u = τ − Sᵀ p^A)
  double pivot = 0;          // its pivot of D = W Δ Wᵀ (the joint's last rate eliminated first)
};

struct Workspace {
  explicit Workspace(const Model& model);

  VecX theta, theta_dot, theta_dot_y;  // θ, θ̇ (= C x), C y
  // The reference point o (world) of the last propagate: the origin of the first body, so that
  // every position the algorithms use (BodyState::p, nodes, attachments, spatial inertias and
  // motions "about the origin") is measured from the mechanism itself. The equations do not
  // depend on o; their round-off would grow as m·|p|² with positions taken from the world's
  // origin (a robot 1 km away). Positions handed out (frames, centre of mass, poses, energy)
  // add o back.
  Vec3 origin = Vec3::Zero();
  std::vector<BodyState> body;  // per body
  MatX Jw, Jv;                  // body Jacobians in q: rows 3b..3b+2 of body b (3nb x n),
                                // sized when first formed
  MatX T;                       // T = ∂u/∂q (N_u x n), sized when first formed
  VecX bias;                    // T'[q̇,q̇] (N_u)
  VecX u_dot;                   // u̇ = T q̇
  VecX nodal;                   // M T'[q̇,q̇] + g, then nodal forces F (N_u)
  MatX MT;                      // M T (N_u x n), sized when first formed
  VecX u_acc;                   // T q̈ + T'[q̇,q̇] (inverse dynamics); also the nodal forces
                                // plus the body torques in generalized_force (N_u)
  std::vector<RigidInertia> composite;  // per body: composite inertia I^c_b (world, origin)
  std::vector<Vec6> subspace;  // per rate of θ̇: its column of S (world, origin), at the joint's
                               // idx_v (core/joints/kernel.hpp)
  std::vector<ArticulatedBody> articulated;           // per body, for the body-level routes only
  std::vector<ArticulatedRate> articulated_rate;      // per rate, on the articulated route with a
                                                      // joint of several rates only
  std::vector<Vec6> solve_force, solve_acceleration;  // per body, articulated_solve's p and a
  std::vector<Vec3> force, moment;  // per body: wrench of Tᵀ f (world; moment about the origin)
  VecX tau_theta;                   // Tᵀ f on the joint coordinates θ
  std::vector<VecX> local_x, local_y, local_g;  // per element local DOF buffers (6k)

  // System equations M^s q̈ + h = Q at the last evaluated state.
  MatX Ms;  // sized on first use (evaluate, mass_matrix)
  VecX h, Q, qdd, tau;
  MassSolver solver;  // factorisation of M^s (dense or CHOLMOD, chosen for the model)

  // Two-point springs (core/dynamics/springs.hpp): their generalized force Q_s, τ + Q_s for the
  // routes, the power their dampers dissipate at the last evaluation, and the ends' motions.
  VecX Q_springs, tau_applied;
  double spring_power = 0;
  AttachmentMotion end_a, end_b;

  // With a nonlinear coupling level (Model::tree): the tree's workspace, g's derivatives, and
  // the factorisation of the reduced M^s = Gᵀ M_θ G.
  std::unique_ptr<Workspace> tree;
  std::unique_ptr<CouplingLevelState> level;
  Eigen::LLT<MatX> reduced;
};

}  // namespace femdyn
