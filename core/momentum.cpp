#include "core/momentum.hpp"

#include <Eigen/LU>

#include "core/errors.hpp"
#include "core/kinematics.hpp"

namespace femdyn {

namespace {

// A node's place in world: x = p_b + R_b r.
Vec3 node_position(const Model& model, const Workspace& ws, int node) {
  const SystemNode& N = model.nodes[node];
  const BodyState& B = ws.body[N.body];
  return B.p + B.R * N.r;
}

// G ξ_c for the six unit twists about the world origin (linear x y z, then angular x y z):
// one row of G per transition coordinate u_i (the map in core/momentum.hpp).
Vec6 rigid_motion_map(const Model& model, const Workspace& ws, int i) {
  const SystemDof& d = model.dofs[i];
  Vec6 row = Vec6::Zero();
  if (d.kind == DofKind::Translation) {
    const Vec3 x = node_position(model, ws, d.carrier);
    row[d.axis] = 1;                              // e_kᵀ v₀
    row.tail<3>() = x.cross(Vec3::Unit(d.axis));  // e_kᵀ (ω × x) = (x × e_k)ᵀ ω
  } else {
    row.tail<3>() = ws.body[d.carrier].R.col(d.axis);  // (R_b e_k)ᵀ ω
  }
  return row;
}

// The moment of Ġᵀ f: Σ_trans ẋ × e_k f_i + Σ_rot (ω_b × R_b e_k) f_i.
Vec3 rigid_motion_map_rate(const Model& model, const Workspace& ws, const VecX& f) {
  Vec3 moment = Vec3::Zero();
  for (int i = 0; i < model.n_u(); ++i) {
    if (f[i] == 0) continue;
    const SystemDof& d = model.dofs[i];
    if (d.kind == DofKind::Translation) {
      const SystemNode& N = model.nodes[d.carrier];
      const BodyState& B = ws.body[N.body];
      const Vec3 xdot = B.v + B.w.cross(B.R * N.r);
      moment += xdot.cross(Vec3::Unit(d.axis)) * f[i];
    } else {
      const BodyState& B = ws.body[d.carrier];
      moment += B.w.cross(B.R.col(d.axis)) * f[i];
    }
  }
  return moment;
}

// The mechanism locked rigid about the origin, Σ_e Σ_l,l' G_lᵀ m_e[l, l'] G_l' over each element's
// nodes l, with G_l = [[1, −[x_l]×], [0, R_bᵀ]] on the node's (x y z, rx ry rz).
Mat6 locked_inertia(const Model& model, const Workspace& ws, MomentumKinematics& out) {
  if (out.masses_of != &model || out.element_mass.size() != model.elements.size()) {
    out.element_mass.clear();
    for (const ElementEntry& e : model.elements)
      out.element_mass.push_back(e.element->local_mass());
    out.masses_of = &model;
  }
  Mat6 I_O = Mat6::Zero();
  for (std::size_t k = 0; k < model.elements.size(); ++k) {
    const ElementEntry& e = model.elements[k];
    const auto nodes = e.element->nodes();
    const auto G = [&](std::size_t l) {
      const BodyState& B = ws.body[e.node_body[l]];
      Mat6 g = Mat6::Zero();
      g.topLeftCorner<3, 3>().setIdentity();
      g.topRightCorner<3, 3>() = -skew(B.p + B.R * nodes[l].position);
      g.bottomRightCorner<3, 3>() = ws.body[e.body].R.transpose();
      return g;
    };
    for (std::size_t l = 0; l < nodes.size(); ++l)
      for (std::size_t j = 0; j < nodes.size(); ++j)
        I_O.noalias() += G(l).transpose() * out.element_mass[k].block<6, 6>(6 * l, 6 * j) * G(j);
  }
  return I_O;
}

// A_O = (MG)ᵀ T without T: each row T_i is its carrier body's Jacobian seen at the DOF,
//   translation: e_kᵀ (Jv_b − [r_w]× Jω_b),   rotation: (R_b e_k)ᵀ Jω_b,
// so (MG)_iᵀ is gathered per body on Jv_b and Jω_b, then A_O = Σ_b Wv_b Jv_b + Ww_b Jω_b.
void momentum_matrix(const Model& model, const Workspace& ws, MomentumKinematics& out) {
  const std::size_t nb = model.bodies.size();
  out.Wv.resize(nb);
  out.Ww.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) out.Wv[b].setZero(), out.Ww[b].setZero();
  for (int i = 0; i < model.n_u(); ++i) {
    const SystemDof& d = model.dofs[i];
    const Vec6 g = out.MG.row(i).transpose();
    if (d.kind == DofKind::Translation) {
      const SystemNode& N = model.nodes[d.carrier];
      const Vec3 rw = ws.body[N.body].R * N.r;
      out.Wv[N.body].col(d.axis) += g;
      out.Ww[N.body].noalias() -= g * skew(rw).row(d.axis);
    } else {
      out.Ww[d.carrier].noalias() += g * ws.body[d.carrier].R.col(d.axis).transpose();
    }
  }
  out.A.setZero(6, model.n());
  for (std::size_t b = 0; b < nb; ++b) {
    const auto bi = static_cast<Eigen::Index>(3 * b);
    out.A.noalias() += out.Wv[b] * ws.Jv.middleRows<3>(bi);
    out.A.noalias() += out.Ww[b] * ws.Jw.middleRows<3>(bi);
  }
}

}  // namespace

void momentum_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v,
                         MomentumKinematics& out) {
  propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
  momentum_kinematics(model, ws, out);
}

void momentum_kinematics(const Model& model, const Workspace& ws, MomentumKinematics& out) {
  const int nu = model.n_u();
  out.G.resize(nu, 6);
  out.MG.resize(nu, 6);
  for (int i = 0; i < nu; ++i) out.G.row(i) = rigid_motion_map(model, ws, i).transpose();
  out.MG.noalias() = model.M * out.G;
  // The locked mechanism: mass, first moment m c, inertia about the origin.
  const Mat6 I_O = locked_inertia(model, ws, out);
  out.mass = I_O.topLeftCorner<3, 3>().trace() / 3;
  if (!(out.mass > 0)) throw StateError(model.name + ": the mechanism has no mass");
  const Mat3 mc_cross = I_O.bottomLeftCorner<3, 3>();  // [m c]×
  const Vec3 mc(mc_cross(2, 1) - mc_cross(1, 2), mc_cross(0, 2) - mc_cross(2, 0),
                mc_cross(1, 0) - mc_cross(0, 1));
  out.com = mc / (2 * out.mass);
  // I_c = I_O − m [c]×ᵀ[c]× (parallel axes)
  out.inertia_com = I_O.bottomRightCorner<3, 3>() + out.mass * skew(out.com) * skew(out.com);

  momentum_matrix(model, ws, out);  // A_O
  out.Mu.noalias() = model.M * ws.u_dot;
  Vec6 h_O, bias_O;
  h_O.noalias() = out.MG.transpose() * ws.u_dot;
  bias_O.noalias() = out.MG.transpose() * ws.bias;
  bias_O.tail<3>() += rigid_motion_map_rate(model, ws, out.Mu);

  // Shift the moment from the origin to c.
  const Mat3 c_cross = skew(out.com);
  out.A.bottomRows<3>().noalias() -= c_cross * out.A.topRows<3>();
  out.momentum << h_O.head<3>(), h_O.tail<3>() - out.com.cross(h_O.head<3>());
  out.bias << bias_O.head<3>(), bias_O.tail<3>() - out.com.cross(bias_O.head<3>());
  out.Jcom = out.A.topRows<3>() / out.mass;
  out.com_velocity = out.momentum.head<3>() / out.mass;
  out.com_bias = out.bias.head<3>() / out.mass;
}

int floating_base_rate(const Model& model) {
  const std::string need = "the generalized Jacobian needs one tree on a free joint at its root";
  int base = -1;
  for (std::size_t b = 0; b < model.bodies.size(); ++b) {
    const Body& B = model.bodies[b];
    if (B.parent < 0 && base >= 0)
      throw ModelError(model.where, need + " (body '" + B.name + "' is a second root)");
    if (B.parent < 0 && B.joint.type != JointType::Free)
      throw ModelError(model.where, need + " (the root '" + B.name + "' is not on a free joint)");
    if (B.parent >= 0 && B.joint.type == JointType::Free)
      throw ModelError(model.where, need + " (body '" + B.name + "' is on a second free joint)");
    if (B.parent < 0) base = static_cast<int>(b);
  }
  if (base < 0) throw ModelError(model.where, need + " (the model has no body)");
  for (const CoordinateJoint& c : model.coordinate_joints)
    if (c.body == base) return c.v;
  throw ModelError(model.where, "the free base owns no coordinates");
}

void generalized_jacobian(const Model& model, const Workspace& ws, int frame, FrameAxes axes,
                          FrameKinematics& frame_out, MomentumKinematics& momentum,
                          GeneralizedJacobian& out) {
  const int base = floating_base_rate(model), n = model.n(), nm = n - 6;
  frame_kinematics(model, ws, frame, axes, frame_out);
  momentum_kinematics(model, ws, momentum);
  const Mat6 A_b = momentum.A.middleCols<6>(base);
  Eigen::FullPivLU<Mat6> lu(A_b);
  if (!lu.isInvertible())
    throw StateError(model.name +
                     ": the generalized Jacobian: A_b, the momentum of the base's "
                     "rates, is singular");
  out.rates.resize(nm);
  for (int k = 0, j = 0; k < n; ++k)
    if (k < base || k >= base + 6) out.rates[j++] = k;
  out.A_m.resize(6, nm);
  out.J.resize(6, nm);
  for (int j = 0; j < nm; ++j) {
    out.A_m.col(j) = momentum.A.col(out.rates[j]);
    out.J.col(j) = frame_out.J.col(out.rates[j]);  // J_m
  }
  const auto J_b = frame_out.J.middleCols<6>(base);
  out.J.noalias() -= J_b * lu.solve(out.A_m);
  out.drift.noalias() = J_b * lu.solve(momentum.momentum);
}

}  // namespace femdyn
