#include "core/articulated.hpp"

#include <algorithm>
#include <cmath>

#include "core/body_inertia.hpp"
#include "core/body_loads.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics.hpp"

namespace femdyn {
namespace {

// τ_b on joint j: the actuation and the joint's spring and damper (C = I: θ = q).
double joint_force(const Joint& J, const Workspace& ws, const VecX& tau) {
  const int j = J.idx_v;
  return (tau.size() > j ? tau[j] : 0.0) +
         spring_damper_force(J, ws.theta[J.idx_q], ws.theta_dot[j]);
}

Status dependent_pivot(const Model& model, int j) {
  return {false,
          "the mass matrix M^s is singular: coordinate '" + model.coordinate_names[j] +
              "' moves no inertia independently of the joints beyond it",
          j};
}

// The Cholesky route's regularity test, exactly: M^s(b, b) = S_bᵀ I^c_b S_b against the largest
// diagonal, and the pivot d_b against M^s(b, b). Only run when the cheap bound was inconclusive.
Status check_regularity(const Model& model, Workspace& ws) {
  const int nb = static_cast<int>(model.bodies.size());
  composite_inertias(model, ws);
  double scale = 0;
  for (int b = 0; b < nb; ++b)
    if (moves(model.bodies[b].joint)) {
      const Vec6& S = ws.articulated[b].S;
      scale = std::max(scale, S.dot(ws.composite[b] * S));
    }
  for (int b = 0; b < nb; ++b) {
    const int j = model.bodies[b].joint.idx_v;
    if (j < 0) continue;
    const Vec6& S = ws.articulated[b].S;
    const double Mbb = S.dot(ws.composite[b] * S);
    if (!std::isfinite(Mbb)) return {false, "the mass matrix M^s has NaN or Inf entries", -1, true};
    if (!(Mbb > 1e-13 * scale)) return negligible_inertia(model.coordinate_names[j], j, Mbb, scale);
  }
  // Pivots in elimination order, leaves first: a lost pivot makes its ancestors' NaN.
  for (int b = nb - 1; b >= 0; --b) {
    const int j = model.bodies[b].joint.idx_v;
    if (j < 0) continue;
    const Vec6& S = ws.articulated[b].S;
    if (!(ws.articulated[b].d >= 1e-13 * S.dot(ws.composite[b] * S)))
      return dependent_pivot(model, j);
  }
  return {};
}

}  // namespace

Status articulated_forward_dynamics(const Model& model, Workspace& ws, const VecX& q,
                                    const VecX& qd, const VecX& tau) {
  const int nb = static_cast<int>(model.bodies.size());
  propagate(model, ws, q, qd, {.jacobian = false, .bias = false, .rows = false});  // poses, θ
  ws.theta_dot = qd;                                                               // C = I

  // 1. Velocities, velocity-product accelerations and bias forces, root to leaves.
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    BodyState& B = ws.body[b];
    A.V = body.parent >= 0 ? ws.articulated[body.parent].V : Vec6::Zero();
    A.c.setZero();
    if (const Joint& J = body.joint; moves(J)) {  // one rate (choose_routes)
      A.S = spatial_column(J, B.R, parent_rotation(model, ws.body, b), B.p, 0);
      const Vec6 vj = A.S * ws.theta_dot[J.idx_v];
      A.V += vj;
      A.c = cross_motion(A.V, vj);
    }
    B.w = A.V.head<3>();
    const RigidInertia I = inertia_at_origin(model.body_inertia[b], B.R, B.p);
    A.IA = I.matrix();
    A.trace = I.I.trace() + 3 * I.m;
    A.pA = cross_force(A.V, I * A.V);
  }
  subtract_body_loads(model, ws);

  // 2. Articulated inertias and bias forces, leaves to root.
  for (int b = nb - 1; b >= 0; --b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    const int p = body.parent;
    if (moves(body.joint)) {
      A.U = A.IA * A.S;
      A.d = A.S.dot(A.U);
      A.u = joint_force(body.joint, ws, tau) - A.S.dot(A.pA);
      if (p < 0) continue;
      A.IA.noalias() -= (A.U / A.d) * A.U.transpose();  // I^a = I^A − U Uᵀ / d
      A.pA.noalias() += A.IA * A.c + A.U * (A.u / A.d);
    } else if (p < 0) {
      continue;
    }
    ws.articulated[p].IA += A.IA;
    ws.articulated[p].pA += A.pA;
    ws.articulated[p].trace += A.trace;
  }

  // Regularity. M^s(b, b) = S_bᵀ I^c_b S_b ≤ tr(I^c_b) |S_b|², so a pivot above 1e-13 of that
  // bound passes the Cholesky route's test; otherwise that test is run exactly.
  for (int b = 0; b < nb; ++b) {
    const ArticulatedBody& A = ws.articulated[b];
    if (!moves(model.bodies[b].joint)) continue;
    if (!(A.d > 1e-13 * A.trace * A.S.squaredNorm() && std::isfinite(A.u))) {
      if (Status st = check_regularity(model, ws); !st.ok) return st;
      break;
    }
  }

  // 3. Accelerations, root to leaves, from the base acceleration −g that stands for gravity.
  const Vec6 a_base = gravity_base_acceleration(model);
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    A.a = (body.parent >= 0 ? ws.articulated[body.parent].a : a_base) + A.c;
    if (!moves(body.joint)) continue;
    const double qdd = (A.u - A.U.dot(A.a)) / A.d;
    ws.qdd[body.joint.idx_v] = qdd;
    A.a += A.S * qdd;
  }
  return {};
}

}  // namespace femdyn
