// The constant external loads at the body level (core/dynamics/articulated.hpp,
// core/dynamics/newton_euler.hpp).
//
// Gravity: the nodal gravity forces are F = M G (every translation DOF accelerates by g,
// compile/correlation.cpp), so on each body they sum to Λ_b (0, g): exactly the wrench the
// recursions produce from a base acceleration of −g (Featherstone's device). Point loads and
// body torques, each a wrench on its body, are subtracted from the body's bias force. A
// translation DOF left out of u never moves, so the loads on it do no work either way.
#pragma once
#include "core/model/model.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

// The spatial acceleration of the base that stands for gravity: (0, −g).
inline Vec6 gravity_base_acceleration(const Model& m) {
  Vec6 a;
  a << Vec3::Zero(), -m.gravity;
  return a;
}

// p_b −= the wrench of the point loads and body torques, about the world origin.
inline void subtract_body_loads(const Model& m, Workspace& ws) {
  for (const PointLoad& l : m.point_loads) {
    const BodyState& B = ws.body[l.body];
    ws.articulated[l.body].pA -= wrench_at_origin(B.p + B.R * l.point, l.force);
  }
  for (const BodyTorque& t : m.torques) ws.articulated[t.body].pA.head<3>() -= t.torque;
}

}  // namespace femdyn
