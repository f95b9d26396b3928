#include "core/kinematics.hpp"

#include "core/coupling.hpp"
#include "core/coupling_chain.hpp"
#include "core/joint.hpp"

namespace femdyn {
namespace {

// Tree level: body poses, rates and biases, parents first.
void propagate_tree(const Model& model, Workspace& ws, KinematicsRequest req) {
  const BodyState root;
  const auto nb = static_cast<Eigen::Index>(model.bodies.size());
  if (req.jacobian && ws.Jw.rows() != 3 * nb) {  // first use only
    ws.Jw.setZero(3 * nb, model.n());
    ws.Jv.setZero(3 * nb, model.n());
  }
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const Joint& j = model.bodies[b].joint;
    const int parent = model.bodies[b].parent;
    const BodyState& P = parent < 0 ? root : ws.body[parent];
    BodyState& B = ws.body[b];

    const Vec3 origin = P.p + P.R * j.p_pj;
    const Vec3 s = P.R * j.axis_parent;  // the joint axis in world (unchanged by its own turn)
    const double th = j.theta >= 0 ? ws.theta[j.theta] : 0.0;
    const double thd = j.theta >= 0 ? ws.theta_dot[j.theta] : 0.0;
    const double thd_y = j.theta >= 0 ? ws.theta_dot_y[j.theta] : 0.0;
    const bool rev = j.type == JointType::Revolute;
    const bool pri = j.type == JointType::Prismatic;

    B.R.noalias() = P.R * joint_rotation(j, th);
    B.p = pri ? Vec3(origin + s * th) : origin;
    const Vec3 r = B.p - P.p;

    if (req.bias) {
      B.w = P.w + (rev ? Vec3(s * thd) : Vec3::Zero());
      B.w_y = P.w_y + (rev ? Vec3(s * thd_y) : Vec3::Zero());
      B.v = P.v + P.w.cross(r) + (pri ? Vec3(s * thd) : Vec3::Zero());
      B.alpha = P.alpha + (rev ? Vec3(P.w_y.cross(s) * thd) : Vec3::Zero());
      B.a = P.a + P.alpha.cross(r) + P.w.cross(P.w_y.cross(r));
      if (pri) B.a += P.w.cross(s) * thd_y + P.w_y.cross(s) * thd;
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
      if (rev) coupling_add_row(model, j.theta, s, Jw);
      if (pri) coupling_add_row(model, j.theta, s, Jv);
    }
  }
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
  if (model.coupling_level) return chain::propagate_bilinear(model, ws, q, x, y, request);
  // Coupling level.
  coupling_apply(model, q, ws.theta, true);
  if (request.bias) {
    coupling_apply(model, x, ws.theta_dot, false);
    coupling_apply(model, y, ws.theta_dot_y, false);
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
    if (j.theta >= 0) {
      const Vec3 s = ws.body[b].R * j.axis;  // the body frame is the joint frame after motion
      ws.tau_theta[j.theta] = s.dot(j.type == JointType::Revolute ? ws.moment[b] : ws.force[b]);
    }
    if (body.parent >= 0) {
      const Vec3 r = ws.body[b].p - ws.body[body.parent].p;
      ws.force[body.parent] += ws.force[b];
      ws.moment[body.parent] += ws.moment[b] + r.cross(ws.force[b]);
    }
  }
  coupling_apply_transpose(model, ws.tau_theta, y);
}

}  // namespace femdyn
