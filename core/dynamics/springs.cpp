#include "core/dynamics/springs.hpp"

#include "core/kinematics/frames.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn {

void spring_forces(const Model& model, Workspace& ws, const VecX& q, const VecX& v) {
  propagate(model, ws, q, v,
            {.jacobian = true, .bias = true, .rows = false});  // (v_A with the bias)
  ws.Q_springs.setZero(model.n());
  ws.spring_power = 0;
  for (const TwoPointSpring& s : model.springs) {
    attachment_motion(model, ws, s.a, ws.end_a);
    attachment_motion(model, ws, s.b, ws.end_b);
    const Vec3 d = ws.end_a.p - ws.end_b.p;
    const double l = d.norm();
    if (!(l > 0)) continue;  // coincident ends: no line to act along
    const Vec3 e = d / l;
    const double l_dot = e.dot(ws.end_a.v - ws.end_b.v);
    const Vec3 f = -(s.stiffness * (l - s.rest_length) + s.damping * l_dot) * e;  // on A
    ws.Q_springs.noalias() += ws.end_a.Jv.transpose() * f;
    ws.Q_springs.noalias() -= ws.end_b.Jv.transpose() * f;
    ws.spring_power -= s.damping * l_dot * l_dot;
  }
}

double spring_potential(const Model& model, Workspace& ws, const VecX& q) {
  const VecX rest = VecX::Zero(model.n());
  propagate(model, ws, q, rest, {.jacobian = false, .bias = false, .rows = false});
  double V = 0;
  for (const TwoPointSpring& s : model.springs) {
    attachment_motion(model, ws, s.a, ws.end_a, false);
    attachment_motion(model, ws, s.b, ws.end_b, false);
    const double stretch = (ws.end_a.p - ws.end_b.p).norm() - s.rest_length;
    V += 0.5 * s.stiffness * stretch * stretch;
  }
  return V;
}

}  // namespace femdyn
