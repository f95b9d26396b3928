// validate_mjcf_import (validation/validate.hpp): an MJCF model against MuJoCo's own compile.
// A model with couplings (an <equality joint> femdyn holds as θ = g(q)) is compared through them:
// MuJoCo keeps every joint a dof, femdyn's equations are MuJoCo's projected on the coupling,
//   M^s = Gᵀ M(θ) G,   τ = Gᵀ τ_MuJoCo(θ, G q̇, G q̈ + γ),   G = ∂θ/∂q, γ = g''[q̇, q̇]
// (docs/design.md#nonlinear-couplings), the equality itself off in the peer. Connect and weld
// equalities (femdyn's loop constraints) are off in the peer too: M^s, τ and q̈ are the spanning
// tree's on both sides.
#include <algorithm>
#include <random>

#include "core/dynamics/equations.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/coupling_level.hpp"
#include "core/model/errors.hpp"
#include "core/workspace/workspace.hpp"
#include "validation/mujoco_peer.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {
namespace {

// The joints' state θ (n_θq), θ̇ = G q̇ and θ̈ = G q̈ + γ at a coordinate state, and G.
struct JointLevel {
  VecX theta, theta_dot, theta_ddot;
  MatX G;
};

// The size of the parts gravity's τ is summed from, |g| m D (D: the largest distance between the
// bodies' origins and centres of mass, from the poses of ws's last propagate): with MuJoCo's
// single-precision mesh vertices, a gravity torque that cancels to near 0 at some posture still
// carries its parts' rounding, so τ is measured against them as h is against bias_floor.
double gravity_floor(const Model& m, const Workspace& ws) {
  if (m.body_inertia.size() != m.bodies.size()) return 0;  // (no body-level form: no floor)
  double mass = 0, reach = 0;
  const Vec3 o = ws.body.empty() ? Vec3::Zero() : ws.body[0].p;
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const RigidInertia& I = m.body_inertia[b];
    const BodyState& B = ws.body[b];
    mass += I.m;
    reach = std::max(reach, (B.p - o).norm());
    if (I.m > 0) reach = std::max(reach, (B.p + B.R * (I.h / I.m) - o).norm());
  }
  return m.gravity.norm() * mass * 2 * reach;
}

JointLevel joint_level(const Model& m, const VecX& q, const VecX& qd, const VecX& qdd) {
  JointLevel j;
  if (m.coupling_level) {
    CouplingLevelState s(*m.coupling_level);
    if (!evaluate_level(*m.coupling_level, q, qd, qd, s))
      throw StateError("a coupling law is not defined at the sampled state");
    j.theta = s.theta;
    j.G = s.G;
    j.theta_dot = s.theta_dot;
    j.theta_ddot = s.G * qdd + s.gamma;
  } else if (m.identity_coupling) {
    j.theta = q;
    j.G = MatX::Identity(m.n(), m.n());
    j.theta_dot = qd;
    j.theta_ddot = qdd;
  } else {
    j.theta = m.C_configuration * q + m.theta0_configuration;
    j.G = MatX(m.C);
    j.theta_dot = j.G * qd;
    j.theta_ddot = j.G * qdd;
  }
  return j;
}

}  // namespace

std::optional<QuantityError> validate_mjcf_import(const Model& m, const std::string& path,
                                                  int mesh_masses, int full_inertias,
                                                  const ValidationOptions& o, std::string& why) {
  std::vector<const Joint*> moving;  // in θ̇ order, as the peer maps them
  for (const Body& b : m.bodies)
    if (b.joint.idx_v >= 0) moving.push_back(&b.joint);
  std::sort(moving.begin(), moving.end(),
            [](const Joint* a, const Joint* b) { return a->idx_v < b->idx_v; });
  std::vector<MujocoPeer::MjcfJoint> joints;
  for (const Joint* j : moving) joints.push_back({j->name, j->nv});
  std::unique_ptr<MujocoPeer> peer;
  try {
    peer = std::make_unique<MujocoPeer>(path, m.gravity, joints);
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
  double tolerance = o.tolerance > 0 ? o.tolerance : pointwise_tolerance(m);
  if (mesh_masses > 0) {  // MuJoCo rounds mesh vertices to float and re-centres them in float
    tolerance = std::max(tolerance, 1e-6);
    why = "the mass of " + std::to_string(mesh_masses) + " mesh geom" +
          (mesh_masses > 1 ? "s" : "") +
          " compared to 1e-6: MuJoCo holds mesh vertices in single precision";
  }
  if (full_inertias > 0 && tolerance < 1e-7) {  // MuJoCo's eig3 stops at about 1e-8
    tolerance = 1e-7;
    why += std::string(why.empty() ? "" : "; ") + std::to_string(full_inertias) +
           " fullinertia compared to 1e-7: MuJoCo's compiler finds a full tensor's principal "
           "axes by an iteration that stops early (1e-10 to 2e-8 measured)";
  }
  if (m.n_theta() != m.n())
    why += std::string(why.empty() ? "" : "; ") + "compared through the couplings: MuJoCo's " +
           std::to_string(m.n_theta()) + " dofs projected on femdyn's " + std::to_string(m.n()) +
           " coordinates (M^s = Gᵀ M G, τ = Gᵀ τ(θ̈ = G q̈ + γ)), the equalities off in MuJoCo";
  QuantityError e{"mujoco", 0, 0, tolerance};
  Workspace ws(m);
  std::mt19937 rng(o.seed);
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), o.qd_scale, rng);
    const VecX qdd = random_uniform(m.n(), 1, rng), tau = random_uniform(m.n(), 1, rng);
    const JointLevel at = joint_level(m, q, qd, qdd);
    const MatX& G = at.G;
    const VecX friction = coulomb_joint_forces(m, at.theta_dot);  // θ level
    const MatX M = peer->mass(at.theta);
    mass_matrix(m, ws, q);
    accumulate(e, ws.Ms, G.transpose() * M * G);
    const double floor = std::max(bias_floor(ws.Ms, qd), mesh_masses ? gravity_floor(m, ws) : 0);
    inverse_dynamics(m, ws, q, qd, qdd);
    accumulate(e, ws.tau,
               G.transpose() * (peer->inverse(at.theta, at.theta_dot, at.theta_ddot) - friction),
               floor);
    // The peer's equalities are off: the spanning tree's q̈ (a model's loops ignored) is compared.
    if (!tree_forward_dynamics(m, ws, q, qd, tau).ok) continue;
    // MuJoCo's q̈ on the coupling: Gᵀ M G q̈ = τ + Gᵀ (friction − τ_MuJoCo(θ, θ̇, θ̈ = γ)).
    const VecX gamma = at.theta_ddot - G * qdd;  // θ̈ at q̈ = 0
    const VecX bias = G.transpose() * (peer->inverse(at.theta, at.theta_dot, gamma) - friction);
    const MatX reduced = G.transpose() * M * G;
    accumulate(e, ws.qdd, reduced.ldlt().solve(tau - bias));
  }
  return e;
}

}  // namespace femdyn::validation
