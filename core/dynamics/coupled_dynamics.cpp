#include "core/dynamics/coupled_dynamics.hpp"

#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/body_loads.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/coupling.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn {

void joint_force_sweeps(const Model& model, Workspace& ws, const VecX* gamma) {
  const int nb = static_cast<int>(model.bodies.size());
  // Root to leaves: V_b, a_b (θ̈ = γ), I_b and the force f_b (kept in pA) the body needs.
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    const BodyState& B = ws.body[b];
    if (body.parent >= 0) {
      A.V = ws.articulated[body.parent].V;
      A.a = ws.articulated[body.parent].a;
    } else {
      A.V.setZero();
      A.a = gravity_base_acceleration(model);
    }
    if (const Joint& J = body.joint; moves(J))
      add_joint_motion(J, B.R, parent_rotation(model, ws.body, b), B.p,
                       ws.theta_dot.data() + J.idx_v, gamma ? gamma->data() + J.idx_v : nullptr,
                       ws.subspace.data() + J.idx_v, A.V, A.a);
    const RigidInertia I = inertia_at_origin(model.body_inertia[b], B.R, B.p);
    A.pA = I * A.a + cross_force(A.V, I * A.V);
    ws.composite[b] = I;
  }
  subtract_body_loads(model, ws);
  // Leaves to root: project on each joint, pass the force and the inertia to the parent.
  for (int b = nb - 1; b >= 0; --b) {
    const Body& body = model.bodies[b];
    const ArticulatedBody& A = ws.articulated[b];
    for (int k = 0; k < body.joint.nv; ++k)
      ws.tau_theta[body.joint.idx_v + k] = ws.subspace[body.joint.idx_v + k].dot(A.pA);
    if (body.parent >= 0) {
      ws.articulated[body.parent].pA += A.pA;
      ws.composite[body.parent] += ws.composite[b];
    }
  }
  // The joints' own forces: a rotor needs I_a γ more; springs, dampers, friction and stops
  // (joints of one coordinate) act against τ_θ.
  for (int j = 0; j < model.n_theta(); ++j) {
    const Joint& J = model.bodies[model.theta_joint[j]].joint;
    if (gamma) ws.tau_theta[j] += J.reflected_inertia * (*gamma)[j];
    if (J.nv == 1) ws.tau_theta[j] -= passive_joint_force(J, ws.theta[J.idx_q], ws.theta_dot[j]);
  }
}

Status coupled_forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                                const VecX& tau) {
  propagate(model, ws, q, qd, {.jacobian = false, .bias = false, .rows = false});  // poses, θ
  coupling_apply(model, qd, ws.theta_dot);
  joint_force_sweeps(model, ws, nullptr);
  coupling_apply_transpose(model, ws.tau_theta, ws.qdd);  // Q − h = τ − Cᵀ τ_θ
  ws.qdd = -ws.qdd;
  if (tau.size() == ws.qdd.size()) ws.qdd += tau;

  if (ws.Ms.rows() != model.n()) ws.Ms.setZero(model.n(), model.n());  // first use only
  mass_from_composites(model, ws);
  const Status st = ws.solver.factorize(ws.Ms);
  if (st.ok) ws.solver.solve_in_place(ws.qdd);
  return st;
}

}  // namespace femdyn
