#include "core/derivatives/springs.hpp"

#include "core/derivatives/derivatives.hpp"
#include "core/derivatives/points.hpp"

namespace femdyn {

void SpringDerivatives::size_for(const Model& m) {
  const auto nt = static_cast<std::size_t>(m.n_theta());
  for (auto* v : {&delta, &du_dq, &arm}) v->assign(nt, Vec3::Zero());
  dl.assign(nt, 0.0);
  dl_dot.assign(nt, 0.0);
  for (auto* v : {&path_a, &path_b, &rates}) v->reserve(nt);
  on_a.assign(nt, 0);
}

namespace {

PointMotion end_of(const Workspace& ws, const DerivativeWorkspace& d, const Attachment& A) {
  if (A.body < 0) return point_motion(d, -1, A.p - ws.origin);  // (from the reference point)
  const BodyState& B = ws.body[A.body];
  return point_motion(d, A.body, B.p + B.R * A.p);
}

// Δ_r += σ J_r(x) and ∂u/∂θ_r += σ ∂ẋ/∂θ_r over the end's path (σ = +1 on A, −1 on B).
void add_end_motion(const Model& m, const DerivativeWorkspace& d, const PointMotion& e, double sign,
                    const std::vector<int>& path, SpringDerivatives& buf) {
  Vec3 dx_dot, dx_ddot;
  for (const int r : path) {
    point_position_derivative(m, d, e, r, dx_dot, dx_ddot);
    buf.delta[r] += sign * point_velocity(d.S[r], e.x);
    buf.du_dq[r] += sign * dx_dot;
  }
}

// The union of the two ends' paths into buf.rates, each rate's Δ and ∂u/∂θ zeroed.
void gather_rates(SpringDerivatives& buf) {
  buf.rates.clear();
  for (const int r : buf.path_a) buf.on_a[r] = 1, buf.rates.push_back(r);
  for (const int r : buf.path_b)
    if (!buf.on_a[r]) buf.rates.push_back(r);
  for (const int r : buf.path_a) buf.on_a[r] = 0;
  for (const int r : buf.rates) buf.delta[r].setZero(), buf.du_dq[r].setZero();
}

void add_spring(const Model& m, const Workspace& ws, const DerivativeWorkspace& d,
                const TwoPointSpring& spring, SpringDerivatives& buf, MatX& Kq, MatX& Kv) {
  const PointMotion a = end_of(ws, d, spring.a), b = end_of(ws, d, spring.b);
  const Vec3 dist = a.x - b.x;
  const double l = dist.norm();
  if (!(l > 0)) return;  // coincident ends: no force (core/dynamics/springs.cpp), no derivative
  const Vec3 e = dist / l, u = a.x_dot - b.x_dot;
  const double k = spring.stiffness, c = spring.damping;
  const double l_dot = e.dot(u), s = k * (l - spring.rest_length) + c * l_dot;
  rates_on_path(m, a.body, buf.path_a);
  rates_on_path(m, b.body, buf.path_b);
  gather_rates(buf);
  add_end_motion(m, d, a, 1.0, buf.path_a, buf);
  add_end_motion(m, d, b, -1.0, buf.path_b, buf);
  for (const int r : buf.rates) {
    buf.dl[r] = e.dot(buf.delta[r]);
    buf.dl_dot[r] = (buf.delta[r] - e * buf.dl[r]).dot(u) / l + e.dot(buf.du_dq[r]);
  }
  // −Δ_cᵀ ∂f/∂θ_m = g_c (k g_m + c ∂ℓ̇/∂θ_m) + (s / ℓ) (Δ_cᵀ Δ_m − g_c g_m); −∂Q_c/∂θ̇_m = c g_c g_m.
  for (const int cr : buf.rates)
    for (const int mr : buf.rates) {
      Kq(cr, mr) += buf.dl[cr] * (k * buf.dl[mr] + c * buf.dl_dot[mr]) +
                    s / l * (buf.delta[cr].dot(buf.delta[mr]) - buf.dl[cr] * buf.dl[mr]);
      Kv(cr, mr) += c * buf.dl[cr] * buf.dl[mr];
    }
  // τ has −f at A and +f at B (f = −s ê the force on A): their Jacobians turn.
  const Vec3 f = -s * e;
  add_point_turning(m, d, a.x, -f, buf.path_a, buf.arm, Kq);
  add_point_turning(m, d, b.x, f, buf.path_b, buf.arm, Kq);
}

}  // namespace

void add_spring_derivatives(const Model& m, const Workspace& ws, DerivativeWorkspace& d, MatX& Kq,
                            MatX& Kv) {
  for (const TwoPointSpring& spring : m.springs) add_spring(m, ws, d, spring, d.springs, Kq, Kv);
}

}  // namespace femdyn
