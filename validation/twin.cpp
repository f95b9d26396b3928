// The Simbody twin (twin.hpp): its equations, inverse dynamics and timing entry points. The
// mechanism, couplings, state mapping and trajectories are in the files twin_impl.hpp lists.
// Compiled without NDEBUG: Debian's Simbody 3.7 is built without it and some of its header
// classes change layout with it (see CMakeLists.txt).
#include "validation/twin.hpp"

#include <Simbody.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/model/names.hpp"
#include "validation/twin_impl.hpp"

namespace femdyn::validation {

std::string one_line(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    const auto end = line.find_last_not_of(" \t\r");
    line = line.substr(begin, end + 1 - begin);
    if (line.rfind("SimTK Exception thrown at ", 0) == 0) continue;
    out += (out.empty() ? "" : " ") + line;
  }
  return out;
}

SimbodyTwin::SimbodyTwin(TwinModel model) : impl_(std::make_unique<Impl>(std::move(model))) {}
SimbodyTwin::~SimbodyTwin() = default;

TwinEquations SimbodyTwin::equations(const VecX& q, const VecX& qd, const VecX& tau,
                                     const MatX* V) {
  try {
    return equations_unguarded(q, qd, tau, V);
  } catch (const std::exception& e) {  // SimTK's multi-line text, as one line
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
}

TwinEquations SimbodyTwin::equations_unguarded(const VecX& q, const VecX& qd, const VecX& tau,
                                               const MatX* V) {
  Impl& s = *impl_;
  const TwinModel& m = s.model;
  const int n = m.n(), nt = m.n_theta();
  TwinEquations out;
  s.set_state(q, qd, SimTK::Stage::Dynamics);
  if (m.closed_loop()) {
    out = closed_loop_equations(tau);
    if (V) out.MV = out.M * *V;
    return out;
  }

  bool plain = m.n() == nt;  // C = I, θ0 = 0: Simbody's own O(n) forward dynamics applies
  for (int k = 0; k < n && plain; ++k) plain = s.independent[k] == k;
  // Products alone where q̈ needs no M (a coupled tree solves M q̈ = Q − h with it).
  if (V && plain) {  // M V = Cᵀ M_θ C v, column by column, by Simbody's O(n) multiplyByM
    out.MV.resize(n, V->cols());
    SimTK::Vector MV;
    for (Eigen::Index c = 0; c < V->cols(); ++c) {
      s.matter.multiplyByM(s.state, s.expand(V->col(c)), MV);
      out.MV.col(c) = s.reduce(MV);
    }
  } else {  // M = Cᵀ M_θ C
    s.matter.calcM(s.state, s.M_theta);
    MatX Mt(nt, nt);
    for (int a = 0; a < nt; ++a)
      for (int b = 0; b < nt; ++b) Mt(a, b) = s.M_theta(s.theta_u[a], s.theta_u[b]);
    for (std::size_t i = 0; i < s.rotated.size(); ++i) {  // M_v = Pᵀ M_u P
      const int r = s.rotated[i].rate;
      Mt.middleRows<3>(r) = s.rot[i].transpose() * Mt.middleRows<3>(r);
      Mt.middleCols<3>(r) = Mt.middleCols<3>(r) * s.rot[i];
    }
    const MatX MtC = Mt * m.C;
    out.M = m.C.transpose() * MtC;
  }

  // h: residual with no applied force and θ̈ = 0 is the velocity (Coriolis, gyroscopic) term;
  // with v̇ = 0 Simbody's u̇ is Ṗ v, so h_v = Pᵀ (h_u + M_u Ṗ v).
  s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body, s.pdot_v,
                                                s.residual);
  out.h = s.reduce(s.residual);

  // Q: what Simbody's force elements apply, as generalized forces, plus τ on q.
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  SimTK::Vector with_forces;
  s.matter.calcResidualForceIgnoringConstraints(s.state, mob, body, s.pdot_v, with_forces);
  out.Q = s.reduce(s.residual - with_forces) + tau;

  if (plain) {
    // τ on v is P τ on u (P orthogonal); v̇ = Pᵀ (u̇ − Ṗ v).
    SimTK::Vector applied = mob + s.expand(tau);
    s.matter.calcAccelerationIgnoringConstraints(s.state, applied, body, s.udot, s.A_GB);
    out.qdd = s.gather(s.udot - s.pdot_v, s.rot);
  } else {
    out.qdd = out.M.llt().solve(out.Q - out.h);
    if (V) out.MV = out.M * *V, out.M = MatX();
  }
  return out;
}

// v̇ = Pᵀ (u̇ − Ṗ v) on the coordinates' rates.
VecX SimbodyTwin::Impl::constrained_qdd(const SimTK::Vector& applied,
                                        const SimTK::Vector_<SimTK::SpatialVec>& body) {
  matter.calcAcceleration(state, applied, body, udot, A_GB);
  const VecX theta_ddot = gather(udot - pdot_v, rot);
  VecX out(model.n());
  for (int k = 0; k < model.n(); ++k) out[k] = theta_ddot[model.coordinate_theta[k]];
  return out;
}

// A force f on the coordinates' rates as Simbody's mobility forces: P f.
SimTK::Vector SimbodyTwin::Impl::coordinate_forces(const VecX& f) const {
  VecX f_theta = VecX::Zero(model.n_theta());
  for (int k = 0; k < model.n(); ++k) f_theta[model.coordinate_theta[k]] = f[k];
  return scatter(f_theta, rot);
}

MatX SimbodyTwin::Impl::constrained_mass(const VecX& a0) {
  const int n = model.n();
  MatX response(n, n);
  for (int k = 0; k < n; ++k)
    response.col(k) = constrained_qdd(coordinate_forces(VecX::Unit(n, k)), zero_body) - a0;
  return response.partialPivLu().inverse();
}

// The closed loop's equations at the state set by equations_unguarded, from Simbody's
// constrained forward dynamics alone (twin.hpp).
TwinEquations SimbodyTwin::closed_loop_equations(const VecX& tau) {
  Impl& s = *impl_;
  TwinEquations out;
  for (int i = 0; i < s.state.getNQErr(); ++i)
    out.loop_position_error = std::max(out.loop_position_error, std::abs(s.state.getQErr()[i]));
  for (int i = 0; i < s.state.getNUErr(); ++i)
    out.loop_velocity_error = std::max(out.loop_velocity_error, std::abs(s.state.getUErr()[i]));
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  const VecX a0 = s.constrained_qdd(s.zero_mobility, s.zero_body);  // −(M^s)⁻¹ h
  const VecX a_forces = s.constrained_qdd(mob, body);               // (M^s)⁻¹ (Q − τ − h)
  out.M = s.constrained_mass(a0);
  out.h = -out.M * a0;
  out.Q = out.M * (a_forces - a0) + tau;
  out.qdd = s.constrained_qdd(mob + s.coordinate_forces(tau), body);
  return out;
}

VecX SimbodyTwin::inverse_dynamics(const VecX& q, const VecX& qd, const VecX& qdd) {
  try {
    return inverse_dynamics_unguarded(q, qd, qdd);
  } catch (const std::exception& e) {
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
}

VecX SimbodyTwin::inverse_dynamics_unguarded(const VecX& q, const VecX& qd, const VecX& qdd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics);
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  if (s.model.closed_loop()) {  // τ = M^s (q̈ − q̈(Simbody's forces))
    const VecX a_forces = s.constrained_qdd(mob, body);
    const MatX M = s.constrained_mass(s.constrained_qdd(s.zero_mobility, s.zero_body));
    return M * (qdd - a_forces);
  }
  // residual = M_θ θ̈ + h_θ − Q_θ with θ̈ = C q̈;  τ = Cᵀ residual
  // u̇ = P C q̈ + Ṗ v
  s.matter.calcResidualForceIgnoringConstraints(s.state, mob, body, s.expand(qdd) + s.pdot_v,
                                                s.residual);
  return s.reduce(s.residual);
}

void SimbodyTwin::time_mass_and_bias(const VecX& q, const VecX& qd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  s.matter.calcM(s.state, s.M_theta);
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_bias(const VecX& q, const VecX& qd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Velocity, kTiming);
  s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_forward(const VecX& q, const VecX& qd, const VecX& tau) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  s.bench_applied = mob;  // allocates on the first call only
  for (int k = 0; k < s.model.n(); ++k)
    if (s.independent[k] >= 0) s.bench_applied[s.theta_u[s.independent[k]]] += tau[k];
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  if (s.matter.getNumConstraints() == 0)
    s.matter.calcAccelerationIgnoringConstraints(s.state, s.bench_applied, body, s.bench_udot,
                                                 s.bench_A_GB);
  else  // the coupling as coordinate couplers: the constrained (coupled) motion
    s.matter.calcAcceleration(s.state, s.bench_applied, body, s.bench_udot, s.bench_A_GB);
}

void SimbodyTwin::time_inverse(const VecX& q, const VecX& qd, const VecX& qdd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  const int nu = s.state.getNU();
  if (s.bench_theta_ddot.size() != nu) s.bench_theta_ddot = SimTK::Vector(nu, 0.0);
  for (int j = 0; j < s.model.n_theta(); ++j) {
    double theta_ddot = 0;
    for (decltype(s.C_rows)::InnerIterator it(s.C_rows, j); it; ++it)
      theta_ddot += it.value() * qdd[it.col()];
    s.bench_theta_ddot[s.theta_u[j]] = theta_ddot;
  }
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.bench_theta_ddot,
      s.bench_out);
}

void SimbodyTwin::time_mass(const VecX& q) {
  Impl& s = *impl_;
  s.set_state(q, s.rest(), SimTK::Stage::Position, kTiming);
  s.matter.calcM(s.state, s.M_theta);
}

void SimbodyTwin::time_gravity(const VecX& q) {
  Impl& s = *impl_;
  s.set_state(q, s.rest(), SimTK::Stage::Dynamics, kTiming);
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_tensor(const VecX& q) {
  Impl& s = *impl_;
  const int n = s.model.n(), nu = s.state.getNU();
  s.set_state(q, s.rest(), SimTK::Stage::Position, kTiming);
  if (s.bench_h1.nrow() != nu || s.bench_h1.ncol() != n) {  // first call only
    s.bench_h1.resize(nu, n);
    s.bench_D.resize(nu, n * n);
  }
  // h(e_b), b = 1…n: velocity-stage residuals with no force and θ̈ = 0.
  for (int b = 0; b < n; ++b) {
    s.set_unit_rates(b, -1);
    s.system.realize(s.state, SimTK::Stage::Velocity);
    s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                  s.zero_mobility, s.bench_out);
    for (int i = 0; i < nu; ++i) s.bench_h1(i, b) = s.bench_out[i];
  }
  // D_sym(·, b, c) = (h(e_b + e_c) − h(e_b) − h(e_c)) / 2, b ≤ c, mirrored.
  for (int b = 0; b < n; ++b)
    for (int c = b; c < n; ++c) {
      s.set_unit_rates(b, c);
      s.system.realize(s.state, SimTK::Stage::Velocity);
      s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                    s.zero_mobility, s.bench_out);
      for (int i = 0; i < nu; ++i) {
        const double d = 0.5 * (s.bench_out[i] - s.bench_h1(i, b) - s.bench_h1(i, c));
        s.bench_D(i, b * n + c) = d;
        s.bench_D(i, c * n + b) = d;
      }
    }
}

}  // namespace femdyn::validation
