#include "core/dynamics/newton_euler.hpp"

#include "core/dynamics/body_loads.hpp"
#include "core/dynamics/span_inertia.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/coupling.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn {
namespace {

// f = Λ^O a + V ×* Λ^O V, evaluated in the body frame about the body origin, where Λ is three
// numbers (RigidInertia), instead of forming the 6 × 6 Λ^O: the motions move in by
// (ω_b, v_b) = (Rᵀ ω, Rᵀ (v_O + ω × p)) and the force moves out by f = R f_b, n_O = R n_b + p × f.
// (The spatial cross product is the same in any frame.)
Vec6 body_force(const RigidInertia& L, const Mat3& R, const Vec3& p, const Vec6& V, const Vec6& a) {
  const auto to_body = [&](const Vec6& m) {
    Vec6 mb;
    mb.head<3>().noalias() = R.transpose() * m.head<3>();
    mb.tail<3>().noalias() = R.transpose() * (m.tail<3>() + m.head<3>().cross(p));
    return mb;
  };
  const auto inertia_times = [&](const Vec6& m) {  // Λ m = (I ω + h × v, m v − h × ω)
    Vec6 f;
    f.head<3>().noalias() = L.I * m.head<3>();
    f.head<3>() += L.h.cross(m.tail<3>());
    f.tail<3>() = L.m * m.tail<3>() - L.h.cross(m.head<3>());
    return f;
  };
  const Vec6 Vb = to_body(V), ab = to_body(a);
  const Vec6 fb = inertia_times(ab) + cross_force(Vb, inertia_times(Vb));
  Vec6 f;
  f.tail<3>().noalias() = R * fb.tail<3>();
  f.head<3>().noalias() = R * fb.head<3>();
  f.head<3>() += p.cross(f.tail<3>());
  return f;
}

}  // namespace

void newton_euler(const Model& model, Workspace& ws, const VecX& q, const VecX& qd, const VecX* qdd,
                  bool with_external, VecX& y) {
  const int nb = static_cast<int>(model.bodies.size());
  propagate(model, ws, q, qd, {.jacobian = false, .bias = false, .rows = false});  // poses, θ
  coupling_apply(model, qd, ws.theta_dot);
  if (qdd) coupling_apply(model, *qdd, ws.theta_dot_y);  // θ̈ = C q̈ (buffer reused)
  const Vec6 a_base = with_external ? gravity_base_acceleration(model) : Vec6::Zero();

  // Root to leaves: V_b, a_b, and the force f_b (kept in pA) the body needs.
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    BodyState& B = ws.body[b];
    if (body.parent >= 0) {
      A.V = ws.articulated[body.parent].V;
      A.a = ws.articulated[body.parent].a;
    } else {
      A.V.setZero();
      A.a = a_base;
    }
    if (const Joint& J = body.joint; moves(J))  // V += S θ̇_J; a += V × S θ̇_J (+ S θ̈_J)
      add_joint_motion(
          J, B.R, parent_rotation(model, ws.body, b), B.p, ws.theta_dot.data() + J.idx_v,
          qdd ? ws.theta_dot_y.data() + J.idx_v : nullptr, ws.subspace.data() + J.idx_v, A.V, A.a);
    B.w = A.V.head<3>();
    A.pA = body_force(model.body_inertia[b], B.R, B.p, A.V, A.a);
  }
  if (with_external) subtract_body_loads(model, ws);
  // Leaves to root: project on each joint, pass the rest to the parent.
  for (int b = nb - 1; b >= 0; --b) {
    const Body& body = model.bodies[b];
    const ArticulatedBody& A = ws.articulated[b];
    for (int k = 0; k < body.joint.nv; ++k)  // τ_k = S_kᵀ f
      ws.tau_theta[body.joint.idx_v + k] = ws.subspace[body.joint.idx_v + k].dot(A.pA);
    if (body.parent >= 0) ws.articulated[body.parent].pA += A.pA;
  }
  coupling_apply_transpose(model, ws.tau_theta, y);
  add_span_forces(model, ws, y);  // (spanning masses come only with C = I: y is on θ)
}

}  // namespace femdyn
