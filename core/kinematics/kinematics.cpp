#include "core/kinematics/kinematics.hpp"

#include <array>

#include "core/joints/kernel.hpp"
#include "core/kinematics/coupling.hpp"

namespace femdyn {
namespace {

// Tree level, one body: its pose, rates and biases from its parent's, through its joint J
// (core/joints/kernel.hpp). With Δω, Δv the joint's rates at B's origin (world axes) along x
// and along y, and r = p_B − p_P:
//   ω_B = ω_P + Δω(x),   v_B = v_P + ω_P × r + Δv(x)
//   α_B = α_P + ω_B(y) × Δω(x)                                 (d_y of R_B S_ω x)
//   a_B = a_P + α_P × r + ω_P(x) × (ω_P(y) × r + Δv(y)) + ω_B(y) × Δv(x)
// (d_y r = ω_P(y) × r + Δv(y); d_y R_B S_v x = ω_B(y) × Δv(x); S_J is constant in B).
//
// Places are taken from the reference point o = p_pj,0 + d_0, the first body's origin
// (Workspace::origin): a root (a body on the world) is at (p_pj − p_pj,0) + (d_J − d_0), the
// difference of its joint frame's place and the first's (numbers given in the file) plus that of
// the displacements (numbers of the mechanism's size), so that no place loses digits to the
// world's own numbers (a robot 1e6 m out); every other body at p_P + R_P (p_pj + d_J).
struct RootReference {
  Vec3 p_pj = Vec3::Zero(), d = Vec3::Zero();  // the first body's joint frame place and d_0
};

template <class J>
[[gnu::always_inline]] inline void tree_step(const Model& model, Workspace& ws, int b,
                                             const KinematicsRequest& req, const BodyState& root,
                                             RootReference& reference) {
  const Joint& j = model.bodies[b].joint;
  const int parent = model.bodies[b].parent;
  const BodyState& P = parent < 0 ? root : ws.body[parent];
  BodyState& B = ws.body[b];

  Mat3 R_J;
  Vec3 d_J;
  J::pose(j, J::nq > 0 ? ws.theta.data() + j.idx_q : nullptr, R_J, d_J);
  B.R.noalias() = P.R * R_J;
  if (parent >= 0) {
    B.p.noalias() = P.p + P.R * (j.p_pj + d_J);
  } else {
    if (b == 0) {
      reference = {j.p_pj, d_J};
      ws.origin = j.p_pj + d_J;
    }
    B.p = (j.p_pj - reference.p_pj) + (d_J - reference.d);
  }
  const Vec3 r = B.p - P.p;

  std::array<Vec3, J::nv + 1> s_w, s_v;  // the columns of S_J in world axes (one spare: nv = 0)
  if (req.bias || req.jacobian)
    for (int k = 0; k < J::nv; ++k) {
      if constexpr (J::angular) s_w[k] = world_angular<J>(j, B.R, P.R, k);
      if constexpr (J::linear) s_v[k] = world_linear<J>(j, B.R, P.R, k);
    }
  if (req.bias) {
    // The joint's motion at the rates x and y; at x split by the frame each column is fixed in
    // (B or P), whose angular velocity at y turns it (kernel.hpp).
    Vec3 dw_x = Vec3::Zero(), dw_y = Vec3::Zero(), dv_x = Vec3::Zero(), dv_y = Vec3::Zero();
    Vec3 dw_xP = Vec3::Zero(), dv_xP = Vec3::Zero();
    for (int k = 0; k < J::nv; ++k) {
      const double x = ws.theta_dot[j.idx_v + k], y = ws.theta_dot_y[j.idx_v + k];
      if constexpr (J::angular) (J::in_parent(k) ? dw_xP : dw_x) += s_w[k] * x, dw_y += s_w[k] * y;
      if constexpr (J::linear) (J::in_parent(k) ? dv_xP : dv_x) += s_v[k] * x, dv_y += s_v[k] * y;
    }
    B.w = P.w + dw_x + dw_xP;
    B.w_y = P.w_y + dw_y;
    B.v = P.v + cross3(P.w, r) + dv_x + dv_xP;
    B.alpha = P.alpha + cross3(B.w_y, dw_x);
    B.a = P.a + cross3(P.alpha, r) + cross3(P.w, cross3(P.w_y, r) + dv_y) + cross3(B.w_y, dv_x);
    if constexpr (J::in_parent(0) || J::in_parent(J::nv - 1)) {
      B.alpha += cross3(P.w_y, dw_xP);
      B.a += cross3(P.w_y, dv_xP);
    }
  }
  if (req.jacobian) {
    auto Jw = ws.Jw.middleRows<3>(3 * b);
    auto Jv = ws.Jv.middleRows<3>(3 * b);
    if (parent < 0) {
      Jw.setZero();
      Jv.setZero();
    } else {
      Jw = ws.Jw.middleRows<3>(3 * parent);
      Jv = ws.Jv.middleRows<3>(3 * parent);
      Jv.noalias() -= skew(r) * ws.Jw.middleRows<3>(3 * parent);
    }
    for (int k = 0; k < J::nv; ++k) {
      if constexpr (J::angular) coupling_add_row(model, j.idx_v + k, s_w[k], Jw);
      if constexpr (J::linear) coupling_add_row(model, j.idx_v + k, s_v[k], Jv);
    }
  }
}

// Tree level: body poses, rates and biases, parents first.
void propagate_tree(const Model& model, Workspace& ws, KinematicsRequest req) {
  const auto nb = static_cast<Eigen::Index>(model.bodies.size());
  if (req.jacobian && ws.Jw.rows() != 3 * nb) {  // first use only
    ws.Jw.setZero(3 * nb, model.n());
    ws.Jv.setZero(3 * nb, model.n());
  }
  const BodyState root;  // the world (its place is never used: nothing moves it)
  RootReference reference;
  ws.origin.setZero();
  for (int b = 0; b < static_cast<int>(nb); ++b)
    visit_joint(model.bodies[b].joint.type,
                [&]<class J>(J) { tree_step<J>(model, ws, b, req, root, reference); });
}

// Node level: rows of T, T'[q̇,q̇] and u̇ for every kept transition coordinate.
void propagate_nodes(const Model& model, Workspace& ws, KinematicsRequest req) {
  req.jacobian = req.jacobian && req.rows;
  if (!req.jacobian && !req.bias) return;
  if (req.jacobian && (ws.T.rows() != model.n_u() || ws.T.cols() != model.n()))
    ws.T.setZero(model.n_u(), model.n());  // first use only
  for (std::size_t n = 0; n < model.nodes.size(); ++n) {
    const auto& idx = model.node_dof[n];
    if (idx[0] < 0 && idx[1] < 0 && idx[2] < 0) continue;
    const int b = model.nodes[n].body;
    const BodyState& B = ws.body[b];
    const Vec3 rw = B.R * model.nodes[n].r;
    Vec3 vel, acc;
    if (req.bias) {
      vel = B.v + B.w.cross(rw);
      acc = B.a + B.alpha.cross(rw) + B.w.cross(B.w_y.cross(rw));
    }
    for (int k = 0; k < 3; ++k) {
      const int i = idx[k];
      if (i < 0) continue;
      if (req.jacobian) {
        // e_kᵀ(Jv − [r_w]× Jω) = Jv.row(k) − ([r_w]×).row(k) Jω
        ws.T.row(i) = ws.Jv.row(3 * b + k);
        ws.T.row(i).noalias() -= skew(rw).row(k) * ws.Jw.middleRows<3>(3 * b);
      }
      if (req.bias) {
        ws.u_dot[i] = vel[k];
        ws.bias[i] = acc[k];
      }
    }
  }
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const auto& idx = model.body_rot_dof[b];
    const BodyState& B = ws.body[b];
    if (idx[0] < 0 && idx[1] < 0 && idx[2] < 0) continue;
    const Vec3 alpha_body = req.bias ? Vec3(B.alpha + B.w.cross(B.w_y)) : Vec3::Zero();
    for (int k = 0; k < 3; ++k) {
      const int i = idx[k];
      if (i < 0) continue;
      const Vec3 e = B.R.col(k);  // body axis k in world
      if (req.jacobian) ws.T.row(i).noalias() = e.transpose() * ws.Jw.middleRows<3>(3 * b);
      if (req.bias) {
        ws.u_dot[i] = e.dot(B.w);
        ws.bias[i] = e.dot(alpha_body);
      }
    }
  }
}

}  // namespace

void propagate_bilinear(const Model& model, Workspace& ws, const VecX& q, const VecX& x,
                        const VecX& y, KinematicsRequest request) {
  model.routes.propagate_bilinear(model, ws, q, x, y, request);
}

void propagate_bilinear_levels(const Model& model, Workspace& ws, const VecX& q, const VecX& x,
                               const VecX& y, KinematicsRequest request) {
  // Coupling level.
  coupling_configuration(model, q, ws.theta);
  if (request.bias) {
    coupling_apply(model, x, ws.theta_dot);
    coupling_apply(model, y, ws.theta_dot_y);
  }
  propagate_tree(model, ws, request);
  propagate_nodes(model, ws, request);
  for (const auto& [copy, original] : model.dof_alias) {
    if (request.jacobian && request.rows) ws.T.row(copy) = ws.T.row(original);
    if (request.bias) {
      ws.bias[copy] = ws.bias[original];
      ws.u_dot[copy] = ws.u_dot[original];
    }
  }
}

void propagate(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
               KinematicsRequest request) {
  propagate_bilinear(model, ws, q, qd, qd, request);
}

void apply_transpose(const Model& model, Workspace& ws, const VecX& f, VecX& y,
                     double torque_scale) {
  const int nb = static_cast<int>(model.bodies.size());
  for (int b = 0; b < nb; ++b) ws.force[b].setZero(), ws.moment[b].setZero();
  for (int i = 0; i < model.n_u(); ++i) {
    if (f[i] == 0) continue;
    const SystemDof& d = model.dofs[i];
    if (d.kind == DofKind::Translation) {
      const SystemNode& node = model.nodes[d.carrier];
      const BodyState& B = ws.body[node.body];
      const Vec3 F = f[i] * Vec3::Unit(d.axis);
      ws.force[node.body] += F;
      ws.moment[node.body] += (B.R * node.r).cross(F);
    } else {
      ws.moment[d.carrier] += f[i] * ws.body[d.carrier].R.col(d.axis);
    }
  }
  if (torque_scale != 0)
    for (const BodyTorque& t : model.torques) ws.moment[t.body] += torque_scale * t.torque;
  for (int b = nb - 1; b >= 0; --b) {  // children after parents in the list: leaves first
    const Body& body = model.bodies[b];
    const Joint& j = body.joint;
    const Mat3& R_P = parent_rotation(model, ws.body, b);
    // τ_k = s_ω,k · N_b + s_v,k · F_b: the power of the wrench (about B's origin) per rate.
    visit_joint(j.type, [&]<class J>(J) {
      for (int k = 0; k < J::nv; ++k) {
        double t = 0;
        if constexpr (J::angular) t += world_angular<J>(j, ws.body[b].R, R_P, k).dot(ws.moment[b]);
        if constexpr (J::linear) t += world_linear<J>(j, ws.body[b].R, R_P, k).dot(ws.force[b]);
        ws.tau_theta[j.idx_v + k] = t;
      }
    });
    if (body.parent >= 0) {
      const Vec3 r = ws.body[b].p - ws.body[body.parent].p;
      ws.force[body.parent] += ws.force[b];
      ws.moment[body.parent] += ws.moment[b] + r.cross(ws.force[b]);
    }
  }
  coupling_apply_transpose(model, ws.tau_theta, y);
}

}  // namespace femdyn
