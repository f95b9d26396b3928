#include "core/kinematics/momentum.hpp"

#include <Eigen/LU>

#include "core/kinematics/kinematics.hpp"
#include "core/model/arguments.hpp"
#include "core/model/errors.hpp"

namespace femdyn {

namespace {

// The elements' local masses m_e, read once per model.
void element_masses(const Model& model, MomentumKinematics& out) {
  if (out.masses_of == &model && out.element_mass.size() == model.elements.size()) return;
  out.element_mass.clear();
  for (const ElementEntry& e : model.elements) out.element_mass.push_back(e.element->local_mass());
  out.masses_of = &model;
}

// Node l of an element as the element's mass sees it: y_l = (x y z, rx ry rz), the node's place
// on its body b and the rotation rates of the element's body e in e's axes. A rigid twist
// ξ = (v₀, ω) about the origin moves it by ẏ_l = G_l ξ, G_l = [[1, −[x]×], [0, R_eᵀ]]; the
// mechanism moves it by
//   ẏ_l = (v_b + ω_b × r, R_eᵀ ω_e) = Y_l v,   r = R_b r_B, x = p_b + r,
//   ÿ_l at v̇ = 0: (a_b + α_b × r + ω_b × (ω_b × r), R_eᵀ α_e)   (d/dt R_eᵀ ω_e = R_eᵀ α_e).
struct NodeMotion {
  int body = -1;  // b
  Vec3 r = Vec3::Zero(), x = Vec3::Zero(), xdot = Vec3::Zero();
  Mat6 G = Mat6::Zero();
  Vec6 ydot = Vec6::Zero(), ybias = Vec6::Zero();
};

NodeMotion node_motion(const Workspace& ws, const ElementEntry& e, std::size_t l) {
  const auto nodes = e.element->nodes();
  const BodyState& B = ws.body[e.node_body[l]];
  const BodyState& E = ws.body[e.body];
  NodeMotion out;
  out.body = e.node_body[l];
  out.r = B.R * nodes[l].position;
  out.x = B.p + out.r;
  out.xdot = B.v + B.w.cross(out.r);
  out.G.topLeftCorner<3, 3>().setIdentity();
  out.G.topRightCorner<3, 3>() = -skew(out.x);
  out.G.bottomRightCorner<3, 3>() = E.R.transpose();
  out.ydot << out.xdot, E.R.transpose() * E.w;
  out.ybias << B.a + B.alpha.cross(out.r) + B.w.cross(B.w.cross(out.r)), E.R.transpose() * E.alpha;
  return out;
}

}  // namespace

// Everything from the elements' own masses on their own nodes, so that what u leaves out (a
// node that never moves, a rotation rate that stays 0 while a full inertia tensor couples it to
// the others) still counts. With K_lj = G_lᵀ m_e[l, j]:
//   I_O = Σ G_lᵀ m_e[l, j] G_j            h_O = Σ K_lj ẏ_j
//   A_O = Σ K_lj Y_j, gathered per body on Jv_b, Jω_b (Y_j = [Jv_b − [r]× Jω_b ; R_eᵀ Jω_e])
//   Ȧ_O v = Σ K_lj ÿ_j + Ġ_lᵀ f_l,  f_l = Σ_j m_e[l, j] ẏ_j,  Ġ_lᵀ f = (0, ẋ_l × f_t + ω_e × R_e
//   f_r)
void momentum_kinematics(const Model& model, const Workspace& ws, MomentumKinematics& out) {
  element_masses(model, out);
  const std::size_t nb = model.bodies.size();
  out.Wv.resize(nb);
  out.Ww.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) out.Wv[b].setZero(), out.Ww[b].setZero();
  Mat6 I_O = Mat6::Zero();
  Vec6 h_O = Vec6::Zero(), bias_O = Vec6::Zero();
  for (std::size_t k = 0; k < model.elements.size(); ++k) {
    const ElementEntry& e = model.elements[k];
    const MatX& m_e = out.element_mass[k];
    const BodyState& E = ws.body[e.body];
    const std::size_t nl = e.element->nodes().size();
    for (std::size_t l = 0; l < nl; ++l) {
      const NodeMotion yl = node_motion(ws, e, l);
      Vec6 f = Vec6::Zero();  // f_l
      for (std::size_t j = 0; j < nl; ++j) {
        const NodeMotion yj = j == l ? yl : node_motion(ws, e, j);
        const Mat6 m = m_e.block<6, 6>(6 * l, 6 * j);
        const Mat6 K = yl.G.transpose() * m;
        I_O.noalias() += K * yj.G;
        h_O.noalias() += K * yj.ydot;
        bias_O.noalias() += K * yj.ybias;
        f.noalias() += m * yj.ydot;
        out.Wv[yj.body] += K.leftCols<3>();
        out.Ww[yj.body].noalias() -= K.leftCols<3>() * skew(yj.r);
        out.Ww[e.body].noalias() += K.rightCols<3>() * E.R.transpose();
      }
      bias_O.tail<3>() += yl.xdot.cross(f.head<3>()) + E.w.cross(E.R * f.tail<3>());
    }
  }
  out.A.setZero(6, model.n());
  for (std::size_t b = 0; b < nb; ++b) {
    const auto bi = static_cast<Eigen::Index>(3 * b);
    out.A.noalias() += out.Wv[b] * ws.Jv.middleRows<3>(bi);
    out.A.noalias() += out.Ww[b] * ws.Jw.middleRows<3>(bi);
  }

  // The locked mechanism: mass, first moment m c, inertia about the origin (the reference point
  // o of the body places, Workspace::origin, until c is made a world position below).
  out.mass = I_O.topLeftCorner<3, 3>().trace() / 3;
  if (!(out.mass > 0)) throw StateError(model.name + ": the mechanism has no mass");
  const Mat3 mc_cross = I_O.bottomLeftCorner<3, 3>();  // [m c]×
  const Vec3 mc(mc_cross(2, 1) - mc_cross(1, 2), mc_cross(0, 2) - mc_cross(2, 0),
                mc_cross(1, 0) - mc_cross(0, 1));
  out.com = mc / (2 * out.mass);
  // I_c = I_O − m [c]×ᵀ[c]× (parallel axes)
  out.inertia_com = I_O.bottomRightCorner<3, 3>() + out.mass * skew(out.com) * skew(out.com);

  // Shift the moment from the origin to c.
  const Mat3 c_cross = skew(out.com);
  out.A.bottomRows<3>().noalias() -= c_cross * out.A.topRows<3>();
  out.momentum << h_O.head<3>(), h_O.tail<3>() - out.com.cross(h_O.head<3>());
  out.bias << bias_O.head<3>(), bias_O.tail<3>() - out.com.cross(bias_O.head<3>());
  out.Jcom = out.A.topRows<3>() / out.mass;
  out.com_velocity = out.momentum.head<3>() / out.mass;
  out.com_bias = out.bias.head<3>() / out.mass;
  out.com += ws.origin;  // (about the reference point above: Workspace::origin)
}

void momentum_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v,
                         MomentumKinematics& out) {
  require_state(model, "momentum_kinematics", q, &v);
  propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
  momentum_kinematics(model, ws, out);
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

void generalized_jacobian(const Model& model, const FrameKinematics& frame_out,
                          const MomentumKinematics& momentum, GeneralizedJacobian& out) {
  const int base = floating_base_rate(model), n = model.n(), nm = n - 6;
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
