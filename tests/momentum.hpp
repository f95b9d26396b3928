// The spatial momentum of a condensable model, for the tests of free-floating mechanisms.
#pragma once
#include "core/kinematics/kinematics.hpp"
#include "core/model/model.hpp"
#include "core/spatial/spatial.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn::test {

// Σ_b Λ_b^O V_b: the spatial momentum about the world origin (angular, linear), world axes.
inline Vec6 momentum(const Model& m, Workspace& ws, const VecX& q, const VecX& v) {
  propagate(m, ws, q, v, {.jacobian = false, .bias = true, .rows = false});
  Vec6 h = Vec6::Zero();
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyState& B = ws.body[b];
    const Vec3 p = ws.origin + B.p;  // (world: the workspace holds it from its reference point)
    Vec6 V;
    V << B.w, B.v - B.w.cross(p);
    h += inertia_at_origin(m.body_inertia[b], B.R, p) * V;
  }
  return h;
}

// The centre of mass c = Σ_b (m_b p_b + R_b h_b) / Σ_b m_b, after momentum() or propagate().
inline Vec3 centre_of_mass(const Model& m, const Workspace& ws) {
  Vec3 mc = Vec3::Zero();
  double mass = 0;
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyState& B = ws.body[b];
    mc += m.body_inertia[b].m * (ws.origin + B.p) + B.R * m.body_inertia[b].h;
    mass += m.body_inertia[b].m;
  }
  return mc / mass;
}

// (angular momentum about the centre of mass, linear momentum): L_c = L_O − c × p.
inline Vec6 momentum_about_com(const Model& m, Workspace& ws, const VecX& q, const VecX& v) {
  Vec6 h = momentum(m, ws, q, v);
  h.head<3>() -= centre_of_mass(m, ws).cross(h.tail<3>());
  return h;
}

}  // namespace femdyn::test
