#include "core/integrate.hpp"

#include <algorithm>

namespace femdyn {

Status rk4_step(const Model& model, Workspace& ws, double t, double dt, VecX& q, VecX& qd,
                const Actuation& tau) {
  // Stage i at time t + c_i dt from the state (q, q̇) + a_i dt (k_q, k_q̇) of the previous stage:
  //   k_q = q̇_stage, k_q̇ = q̈(t_stage, q_stage, q̇_stage);   c = a = (0, ½, ½, 1).
  // All buffers live in the workspace: a step allocates nothing.
  static constexpr double c[4] = {0, 0.5, 0.5, 1};
  for (int i = 0; i < 4; ++i) {
    if (i == 0) {
      ws.stage_q = q;
      ws.stage_qd = qd;
    } else {
      ws.stage_q = q + (c[i] * dt) * ws.k_q[i - 1];
      ws.stage_qd = qd + (c[i] * dt) * ws.k_qd[i - 1];
    }
    tau(t + c[i] * dt, ws.stage_tau);
    const Status st = forward_dynamics(model, ws, ws.stage_q, ws.stage_qd, ws.stage_tau);
    if (!st.ok) return st;
    ws.k_q[i] = ws.stage_qd;
    ws.k_qd[i] = ws.qdd;
  }
  q += (dt / 6) * (ws.k_q[0] + 2 * ws.k_q[1] + 2 * ws.k_q[2] + ws.k_q[3]);
  qd += (dt / 6) * (ws.k_qd[0] + 2 * ws.k_qd[1] + 2 * ws.k_qd[2] + ws.k_qd[3]);
  return {};
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
