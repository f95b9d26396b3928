#include "core/dynamics/articulated.hpp"

#include <algorithm>
#include <cmath>

#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/body_loads.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn {
namespace {

// τ_b on joint j: the actuation and the joint's spring and damper (C = I: θ = q).
double joint_force(const Joint& J, const Workspace& ws, const VecX& tau) {
  const int j = J.idx_v;
  return (tau.size() > j ? tau[j] : 0.0) +
         passive_joint_force(J, ws.theta[J.idx_q], ws.theta_dot[j]);
}

Status dependent_pivot(const Model& model, int j) {
  return {false,
          "the mass matrix M^s is singular: coordinate '" + model.coordinate_names[j] +
              "' moves no inertia independently of the joints beyond it",
          j};
}

// Column k of body b's S and its pivot: the scalar route's for one rate, the block's for more.
const Vec6& column(const Model& model, const Workspace& ws, int b, int k) {
  const Joint& J = model.bodies[b].joint;
  return J.nv == 1 ? ws.articulated[b].S : ws.subspace[J.idx_v + k];
}
double pivot(const Model& model, const Workspace& ws, int b, int k) {
  const Joint& J = model.bodies[b].joint;
  return J.nv == 1 ? ws.articulated[b].d : ws.articulated_rate[J.idx_v + k].pivot;
}

// The Cholesky route's regularity test, exactly: M^s(j, j) = S_jᵀ I^c_b S_j against the largest
// diagonal, and the pivot of rate j against M^s(j, j), rates in the tree LTDL's order (leaves
// first, a joint's last rate first). Only run when the cheap bound was inconclusive.
Status check_regularity(const Model& model, Workspace& ws) {
  const int nb = static_cast<int>(model.bodies.size());
  composite_inertias(model, ws);
  double scale = 0;
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < model.bodies[b].joint.nv; ++k) {
      const Vec6& S = column(model, ws, b, k);
      scale = std::max(scale, S.dot(ws.composite[b] * S) + model.bodies[b].joint.reflected_inertia);
    }
  for (int b = 0; b < nb; ++b)
    for (int k = 0; k < model.bodies[b].joint.nv; ++k) {
      const int j = model.bodies[b].joint.idx_v + k;
      const Vec6& S = column(model, ws, b, k);
      const double Mjj = S.dot(ws.composite[b] * S) + model.bodies[b].joint.reflected_inertia;
      if (!std::isfinite(Mjj))
        return {false, "the mass matrix M^s has NaN or Inf entries", -1, true};
      if (!(Mjj > 1e-13 * scale))
        return negligible_inertia(model.coordinate_names[j], j, Mjj, scale);
    }
  // Pivots in elimination order, leaves first: a lost pivot makes its ancestors' NaN.
  for (int b = nb - 1; b >= 0; --b)
    for (int k = model.bodies[b].joint.nv - 1; k >= 0; --k) {
      const Vec6& S = column(model, ws, b, k);
      if (!(pivot(model, ws, b, k) >=
            1e-13 * (S.dot(ws.composite[b] * S) + model.bodies[b].joint.reflected_inertia)))
        return dependent_pivot(model, model.bodies[b].joint.idx_v + k);
    }
  return {};
}

// Step 1 for a joint of several rates: its columns into ws.subspace, V_b and c_b by the kernel.
[[gnu::noinline]] void block_motion(const Model& model, Workspace& ws, int b) {
  const Joint& J = model.bodies[b].joint;
  ArticulatedBody& A = ws.articulated[b];
  const BodyState& B = ws.body[b];
  add_joint_motion(J, B.R, parent_rotation(model, ws.body, b), B.p, ws.theta_dot.data() + J.idx_v,
                   nullptr, ws.subspace.data() + J.idx_v, A.V, A.c);
}

// Step 2 for a joint of N > 1 rates: U = I^A S, D = Sᵀ U (+ its rotor), u = τ − Sᵀ p^A; D = W Δ Wᵀ
// (W unit upper triangular, eliminating the last rate first as the tree LTDL does, so that the
// pivots Δ are the Cholesky route's); K = D⁻¹ Uᵀ, D⁻¹ u and D⁻¹ itself (for articulated_solve) kept
// for step 3, and with a parent, I^A −= U K, p^A += I^a c + U D⁻¹ u. Fixed sizes: no allocation.
template <int N>
void block_step(const Joint& J, ArticulatedBody& A, const Vec6* columns, ArticulatedRate* rates,
                const VecX& tau, bool has_parent) {
  using MatN = Eigen::Matrix<double, N, N>;
  Eigen::Matrix<double, 6, N> S, U;
  for (int k = 0; k < N; ++k) S.col(k) = columns[k];
  U.noalias() = A.IA * S;
  MatN D;
  D.noalias() = S.transpose() * U;
  D.diagonal().array() += J.reflected_inertia;  // D = Sᵀ I^A S + I_a G² (a spherical joint's rotor)
  Eigen::Matrix<double, N, 7 + N> X;  // [Uᵀ u I], solved in place for [K, D⁻¹ u, D⁻¹]
  X.template leftCols<6>() = U.transpose();
  X.template rightCols<N>().setIdentity();
  for (int k = 0; k < N; ++k) {
    const int j = J.idx_v + k;
    X(k, 6) = (tau.size() > j ? tau[j] : 0.0) - columns[k].dot(A.pA);
  }
  MatN W = MatN::Identity();
  for (int a = N - 1; a >= 0; --a) {
    const double d = D(a, a);
    rates[a].pivot = d;
    for (int i = 0; i < a; ++i) W(i, a) = D(i, a) / d;
    for (int i = 0; i < a; ++i)
      for (int k = 0; k <= i; ++k) D(k, i) -= W(i, a) * D(k, a);
  }
  // X ← W⁻ᵀ Δ⁻¹ W⁻¹ X.
  for (int i = N - 2; i >= 0; --i)
    for (int a = i + 1; a < N; ++a) X.row(i) -= W(i, a) * X.row(a);
  for (int i = 0; i < N; ++i) X.row(i) /= rates[i].pivot;
  for (int i = 1; i < N; ++i)
    for (int a = 0; a < i; ++a) X.row(i) -= W(a, i) * X.row(a);
  for (int k = 0; k < N; ++k) {
    rates[k].K = X.template block<1, 6>(k, 0).transpose();
    rates[k].Du = X(k, 6);
    rates[k].Dinv.template head<N>() = X.template block<1, N>(k, 7).transpose();
  }
  if (!has_parent) return;
  A.IA.noalias() -= U * X.template leftCols<6>();  // I^a = I^A − U D⁻¹ Uᵀ
  A.pA.noalias() += A.IA * A.c + U * X.col(6);
}

[[gnu::noinline]] void block_step(const Model& model, Workspace& ws, int b, const VecX& tau) {
  const Body& body = model.bodies[b];
  const Joint& J = body.joint;
  visit_joint(J.type, [&]<class T>(T) {
    if constexpr (T::nv > 1)
      block_step<T::nv>(J, ws.articulated[b], ws.subspace.data() + J.idx_v,
                        ws.articulated_rate.data() + J.idx_v, tau, body.parent >= 0);
  });
}

// Step 3 for a joint of several rates: θ̈ = D⁻¹ u − K a', a = a' + S θ̈.
[[gnu::noinline]] void block_acceleration(const Joint& J, Workspace& ws, ArticulatedBody& A) {
  const Vec6 a = A.a;
  for (int k = 0; k < J.nv; ++k) {
    const int j = J.idx_v + k;
    const ArticulatedRate& r = ws.articulated_rate[j];
    ws.qdd[j] = r.Du - r.K.dot(a);
    A.a += ws.subspace[j] * ws.qdd[j];
  }
}

// The cheap bound of the regularity test for a block: each pivot above 1e-13 tr(I^c) |S_k|².
[[gnu::noinline]] bool block_pivots_clear(const Joint& J, const Workspace& ws,
                                          const ArticulatedBody& A) {
  for (int k = 0; k < J.nv; ++k) {
    const ArticulatedRate& r = ws.articulated_rate[J.idx_v + k];
    if (!(r.pivot > 1e-13 * A.trace * ws.subspace[J.idx_v + k].squaredNorm() &&
          std::isfinite(r.Du)))
      return false;
  }
  return true;
}

// 1. Velocities, velocity-product accelerations and bias forces, root to leaves.
[[gnu::always_inline]] inline void articulated_velocities(const Model& model, Workspace& ws) {
  const int nb = static_cast<int>(model.bodies.size());
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    BodyState& B = ws.body[b];
    A.V = body.parent >= 0 ? ws.articulated[body.parent].V : Vec6::Zero();
    A.c.setZero();
    if (const Joint& J = body.joint; J.nv == 1) {
      A.S = spatial_column(J, B.R, parent_rotation(model, ws.body, b), B.p, 0);
      const Vec6 vj = A.S * ws.theta_dot[J.idx_v];
      A.V += vj;
      A.c = cross_motion(A.V, vj);
    } else if (moves(J)) {
      block_motion(model, ws, b);
    }
    B.w = A.V.head<3>();
    const RigidInertia I = inertia_at_origin(model.body_inertia[b], B.R, B.p);
    A.IA = I.matrix();
    A.trace = I.I.trace() + 3 * I.m;
    A.pA = cross_force(A.V, I * A.V);
    A.I = I;  // kept for the derivatives (core/derivatives/derivatives.cpp)
  }
}

// 2. Articulated inertias and bias forces, leaves to root.
[[gnu::always_inline]] inline void articulated_inertias(const Model& model, Workspace& ws,
                                                        const VecX& tau) {
  const int nb = static_cast<int>(model.bodies.size());
  for (int b = nb - 1; b >= 0; --b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    const int p = body.parent;
    if (body.joint.nv == 1) {
      A.U = A.IA * A.S;
      A.d = A.S.dot(A.U) + body.joint.reflected_inertia;  // D = Sᵀ I^A S + I_a G²
      A.u = joint_force(body.joint, ws, tau) - A.S.dot(A.pA);
      if (p < 0) continue;
      A.IA.noalias() -= (A.U / A.d) * A.U.transpose();  // I^a = I^A − U Uᵀ / d
      A.pA.noalias() += A.IA * A.c + A.U * (A.u / A.d);
    } else if (moves(body.joint)) {
      block_step(model, ws, b, tau);
      if (p < 0) continue;
    } else if (p < 0) {
      continue;
    }
    ws.articulated[p].IA += A.IA;
    ws.articulated[p].pA += A.pA;
    ws.articulated[p].trace += A.trace;
  }
}

// Regularity. M^s(j, j) = S_jᵀ I^c_b S_j ≤ tr(I^c_b) |S_j|², so a pivot above 1e-13 of that
// bound passes the Cholesky route's test; otherwise that test is run exactly.
[[gnu::always_inline]] inline Status articulated_regularity(const Model& model, Workspace& ws) {
  const int nb = static_cast<int>(model.bodies.size());
  for (int b = 0; b < nb; ++b) {
    const ArticulatedBody& A = ws.articulated[b];
    const Joint& J = model.bodies[b].joint;
    if (J.nv == 1 ? A.d > 1e-13 * A.trace * A.S.squaredNorm() && std::isfinite(A.u)
                  : !moves(J) || block_pivots_clear(J, ws, A))
      continue;
    return check_regularity(model, ws);
  }
  return {};
}

// 3. Accelerations, root to leaves, from the base acceleration −g that stands for gravity.
[[gnu::always_inline]] inline void articulated_accelerations(const Model& model, Workspace& ws) {
  const int nb = static_cast<int>(model.bodies.size());
  const Vec6 a_base = gravity_base_acceleration(model);
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    ArticulatedBody& A = ws.articulated[b];
    A.a = (body.parent >= 0 ? ws.articulated[body.parent].a : a_base) + A.c;
    if (body.joint.nv == 1) {
      const double qdd = (A.u - A.U.dot(A.a)) / A.d;
      ws.qdd[body.joint.idx_v] = qdd;
      A.a += A.S * qdd;
    } else if (moves(body.joint)) {
      block_acceleration(body.joint, ws, A);
    }
  }
}

}  // namespace

Status articulated_forward_dynamics(const Model& model, Workspace& ws, const VecX& q,
                                    const VecX& qd, const VecX& tau) {
  propagate(model, ws, q, qd, {.jacobian = false, .bias = false, .rows = false});  // poses, θ
  ws.theta_dot = qd;                                                               // C = I
  articulated_velocities(model, ws);
  subtract_body_loads(model, ws);
  articulated_inertias(model, ws, tau);
  if (Status st = articulated_regularity(model, ws); !st.ok) return st;
  articulated_accelerations(model, ws);
  return {};
}

void articulated_solve(const Model& model, Workspace& ws, VecX& x) {
  const int nb = static_cast<int>(model.bodies.size());
  // Leaves to root: u = f − Sᵀ p, p_parent += p + U D⁻¹ u (the articulated forces of f alone).
  for (int b = 0; b < nb; ++b) ws.solve_force[b].setZero();
  for (int b = nb - 1; b >= 0; --b) {
    const Body& body = model.bodies[b];
    const Joint& J = body.joint;
    const ArticulatedBody& A = ws.articulated[b];
    Vec6& p = ws.solve_force[b];
    if (J.nv == 1) {
      x[J.idx_v] -= A.S.dot(p);  // u_b
      p += A.U * (x[J.idx_v] / A.d);
    } else {
      for (int k = 0; k < J.nv; ++k) x[J.idx_v + k] -= ws.subspace[J.idx_v + k].dot(p);
      for (int k = 0; k < J.nv; ++k) p += ws.articulated_rate[J.idx_v + k].K * x[J.idx_v + k];
    }
    if (body.parent >= 0) ws.solve_force[body.parent] += p;
  }
  // Root to leaves: ẍ = D⁻¹ u − D⁻¹ Uᵀ a, a += S ẍ (a_0 = 0: no gravity, no velocity).
  for (int b = 0; b < nb; ++b) {
    const Body& body = model.bodies[b];
    const Joint& J = body.joint;
    const ArticulatedBody& A = ws.articulated[b];
    Vec6& a = ws.solve_acceleration[b];
    a = body.parent >= 0 ? ws.solve_acceleration[body.parent] : Vec6::Zero();
    if (J.nv == 1) {
      x[J.idx_v] = (x[J.idx_v] - A.U.dot(a)) / A.d;
      a += A.S * x[J.idx_v];
    } else if (J.nv > 1) {
      Vec6 u = Vec6::Zero();
      u.head(J.nv) = x.segment(J.idx_v, J.nv);
      for (int k = 0; k < J.nv; ++k) {
        const ArticulatedRate& r = ws.articulated_rate[J.idx_v + k];
        x[J.idx_v + k] = r.Dinv.dot(u) - r.K.dot(a);
      }
      for (int k = 0; k < J.nv; ++k) a += ws.subspace[J.idx_v + k] * x[J.idx_v + k];
    }
  }
}

}  // namespace femdyn
