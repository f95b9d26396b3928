#include "core/integrate.hpp"

#include <algorithm>

namespace femdyn {

Status rk4_step(const Model& model, Workspace& ws, double t, double dt, VecX& q, VecX& qd,
                const Actuation& tau) {
  const int n = model.n();
  VecX u(n), k1v(n), k2v(n), k3v(n), k4v(n), k1a(n), k2a(n), k3a(n), k4a(n);
  auto accel = [&](double tt, const VecX& qq, const VecX& vv, VecX& a) {
    tau(tt, u);
    Status st = forward_dynamics(model, ws, qq, vv, u);
    a = ws.qdd;
    return st;
  };
  Status st;
  k1v = qd;
  if (!(st = accel(t, q, k1v, k1a)).ok) return st;
  k2v = qd + 0.5 * dt * k1a;
  if (!(st = accel(t + 0.5 * dt, q + 0.5 * dt * k1v, k2v, k2a)).ok) return st;
  k3v = qd + 0.5 * dt * k2a;
  if (!(st = accel(t + 0.5 * dt, q + 0.5 * dt * k2v, k3v, k3a)).ok) return st;
  k4v = qd + dt * k3a;
  if (!(st = accel(t + dt, q + dt * k3v, k4v, k4a)).ok) return st;
  q += dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
  qd += dt / 6 * (k1a + 2 * k2a + 2 * k3a + k4a);
  return st;
}

void quintic(const VecX& q0, const VecX& q1, double T, double t, VecX& q, VecX& qd, VecX& qdd) {
  const double x = std::clamp(t / T, 0.0, 1.0);
  const double s = x * x * x * (10 - 15 * x + 6 * x * x);
  const double ds = 30 * x * x * (1 - x) * (1 - x) / T;
  const double dds = 60 * x * (1 - x) * (1 - 2 * x) / (T * T);
  q = q0 + (q1 - q0) * s;
  qd = (q1 - q0) * ds;
  qdd = (q1 - q0) * dds;
}

}  // namespace femdyn
