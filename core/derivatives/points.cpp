#include "core/derivatives/points.hpp"

#include "core/derivatives/derivatives.hpp"
#include "core/joints/kernel.hpp"

namespace femdyn {

void rates_on_path(const Model& m, int b, std::vector<int>& path) {
  path.clear();
  while (b >= 0 && !moves(m.bodies[b].joint)) b = m.bodies[b].parent;
  if (b < 0) return;
  const Joint& J = m.bodies[b].joint;
  for (int r = J.idx_v + J.nv - 1; r >= 0; r = m.rate_parent[r]) path.push_back(r);
}

namespace {

// Whether column c moves with θ_m, for c at position i and m at position j (deepest first) of
// one path: c below m's joint, or of m's joint and fixed in its body.
bool moves_with(const Model& m, const std::vector<int>& path, std::size_t i, std::size_t j) {
  const int c = path[i], b = m.theta_joint[c];
  if (b != m.theta_joint[path[j]]) return i < j;
  const Joint& J = m.bodies[b].joint;
  return !column_in_parent(J, c - J.idx_v);
}

}  // namespace

void add_point_turning(const Model& m, const DerivativeWorkspace& d, const Vec3& x, const Vec3& F,
                       const std::vector<int>& path, std::vector<Vec3>& arm, MatX& Kq) {
  for (const int r : path) arm[r] = point_velocity(d.S[r], x).cross(F);  // J_r × F
  for (std::size_t i = 0; i < path.size(); ++i)
    for (std::size_t j = 0; j < path.size(); ++j) {
      const int c = path[i], mr = path[j];
      Kq(c, mr) +=
          moves_with(m, path, i, j) ? d.S[mr].head<3>().dot(arm[c]) : d.S[c].head<3>().dot(arm[mr]);
    }
}

PointMotion point_motion(const DerivativeWorkspace& d, int body, const Vec3& x) {
  PointMotion p;
  p.body = body;
  p.x = x;
  if (body < 0) return p;  // on the world: at rest (ẍ − g is not used there)
  const Vec6 &V = d.V[body], &a = d.a[body];
  p.x_dot = point_velocity(V, x);
  p.x_ddot = point_velocity(a, x) + V.head<3>().cross(p.x_dot);
  return p;
}

void add_axis_turning(const Model& m, const DerivativeWorkspace& d, const Vec3& t,
                      const std::vector<int>& path, MatX& Kq) {
  for (std::size_t i = 0; i < path.size(); ++i)
    for (std::size_t j = 0; j < path.size(); ++j)
      if (moves_with(m, path, i, j))
        Kq(path[i], path[j]) += d.S[path[j]].head<3>().cross(d.S[path[i]].head<3>()).dot(t);
}

void body_position_derivative(const Model& m, const DerivativeWorkspace& d, int body, int r,
                              Vec6& dV, Vec6& da) {
  const int rb = m.theta_joint[r];
  const Vec6 &S = d.S[r], &V = d.V[body], &a = d.a[body];
  const Vec6 &V_bar = d.V_bar[rb], &a_bar = d.a_bar[rb];
  dV = cross_motion(S, V - V_bar);
  da = cross_motion(S, a - a_bar) + cross_motion(cross_motion(V_bar, S), V - V_bar);
}

Vec6 body_rate_derivative(const Model& m, const DerivativeWorkspace& d, int body, int r) {
  const int rb = m.theta_joint[r], parent = m.bodies[rb].parent;
  const Joint& J = m.bodies[rb].joint;
  const Vec6 &S = d.S[r], &V = d.V[body], &V_bar = d.V_bar[rb];
  const Vec6 V_f = !column_in_parent(J, r - J.idx_v) ? d.V[rb]
                   : parent >= 0                     ? d.V[parent]
                                                     : Vec6::Zero().eval();
  return cross_motion(V_f, S) + cross_motion(S, V - V_bar);
}

void point_position_derivative(const Model& m, const DerivativeWorkspace& d, const PointMotion& p,
                               int r, Vec3& dx_dot, Vec3& dx_ddot) {
  const Vec6 &S = d.S[r], &V = d.V[p.body], &a = d.a[p.body];
  Vec6 dV, da;
  body_position_derivative(m, d, p.body, r, dV, da);
  const Vec3 dx = point_velocity(S, p.x), w = V.head<3>();
  dx_dot = point_velocity(dV, p.x) + w.cross(dx);
  dx_ddot = point_velocity(da, p.x) + a.head<3>().cross(dx) + dV.head<3>().cross(p.x_dot) +
            w.cross(dx_dot);
}

Vec3 point_rate_derivative(const Model& m, const DerivativeWorkspace& d, const PointMotion& p,
                           int r) {
  const Vec6 &S = d.S[r], &V = d.V[p.body];
  const Vec6 da = body_rate_derivative(m, d, p.body, r);
  const Vec3 w = V.head<3>();
  // ∂ω = S_ω, ∂ẋ = J_r(x), ∂x = 0
  return point_velocity(da, p.x) + S.head<3>().cross(p.x_dot) + w.cross(point_velocity(S, p.x));
}

}  // namespace femdyn
