// The twin's state mapping (twin_impl.hpp): femdyn's q, q̇ (and θ, θ̇) to and from Simbody's
// state, and the maps by C and Cᵀ between q and Simbody's u layout. Compiled like twin.cpp
// (C++17, without NDEBUG).
#include <Simbody.h>

#include <algorithm>

#include "core/model/errors.hpp"
#include "validation/twin_impl.hpp"
#include "validation/twin_loops.hpp"

namespace femdyn::validation {

namespace {

// Where coordinate k (rate k) of a femdyn joint sits among its mobilizer's q (u): planar
// (x, y, θ) against Simbody's (θ, x, y); free (p, quaternion), (v, ω) against (quaternion, p),
// (ω, v); the others in the same order.
int q_offset(TwinBody::Joint type, int k) {
  if (type == TwinBody::Joint::Planar) return (k + 1) % 3;
  if (type == TwinBody::Joint::Free) return k < 3 ? 4 + k : k - 3;
  return k;
}
int u_offset(TwinBody::Joint type, int k) {
  if (type == TwinBody::Joint::Planar) return (k + 1) % 3;
  if (type == TwinBody::Joint::Free) return (k + 3) % 6;
  return k;
}

}  // namespace

void SimbodyTwin::Impl::finish_state() {
  using namespace SimTK;
  const TwinModel& m = model;
  state = system.realizeTopology();
  system.realizeModel(state);
  theta_q.assign(std::max(m.n_theta_q, m.n_theta()), -1);
  theta_u.assign(m.n_theta(), -1);
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const TwinBody& tb = m.bodies[b];
    if (tb.theta < 0) continue;
    const int rate = tb.rate >= 0 ? tb.rate : tb.theta;  // one index when nq = nv
    const int q0 = mobod[b].getFirstQIndex(state), u0 = mobod[b].getFirstUIndex(state);
    const int nq = mobod[b].getNumQ(state), nu = mobod[b].getNumU(state);
    for (int k = 0; k < nq; ++k) theta_q[tb.theta + k] = q0 + q_offset(tb.joint, k);
    for (int k = 0; k < nu; ++k) theta_u[rate + k] = u0 + u_offset(tb.joint, k);
    if (tb.joint == TwinBody::Joint::Spherical) rotated.push_back({q0, rate, false});
    if (tb.joint == TwinBody::Joint::Free)
      rotated.push_back({q0, rate, true}), rotated.push_back({q0, rate + 3, false});
  }
  theta_q.resize(m.n_theta_q > 0 ? m.n_theta_q : m.n_theta());
  rot.assign(rotated.size(), ::Eigen::Matrix3d::Identity());
  if (!rotated.empty() && !m.closed_loop()) configuration_coupling();
  const int nu = state.getNU();
  zero_mobility = Vector(nu, 0.0);
  pdot_v = zero_mobility;
  zero_body =
      Vector_<SpatialVec>(matter.getNumBodies(), SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0)));
}

// θ = C_q q + θ0_q: a ball's or free joint's entries copied from q, every other joint's θ from
// C's row on the entries of q its coordinates sit at.
void SimbodyTwin::Impl::configuration_coupling() {
  const TwinModel& m = model;
  const std::vector<int> own = independent_thetas(m);  // coordinate k -> its joint's rate
  int n_q = 0;
  const std::vector<int> first = m.configuration_layout(own, n_q);
  const auto q_at = [&](int k) {  // coordinate k's entry of q (on a joint with nq = nv)
    const TwinBody& tb = m.bodies[m.theta_body[own[k]]];
    return first[m.theta_body[own[k]]] + (own[k] - (tb.rate >= 0 ? tb.rate : tb.theta));
  };
  std::vector<::Eigen::Triplet<double>> entries;
  theta0_configuration = VecX::Zero(m.n_theta_q);
  for (std::size_t b = 0; b < m.bodies.size(); ++b) {
    const TwinBody& tb = m.bodies[b];
    if (tb.theta < 0) continue;
    if (tb.joint == TwinBody::Joint::Spherical || tb.joint == TwinBody::Joint::Free) {
      for (int k = 0; k < coordinates_of(tb.joint); ++k)
        entries.emplace_back(tb.theta + k, first[b] + k, 1.0);
      continue;
    }
    const int rate = tb.rate >= 0 ? tb.rate : tb.theta;
    for (int k = 0; k < coordinates_of(tb.joint); ++k) {
      theta0_configuration[tb.theta + k] = m.theta0[rate + k];
      for (decltype(C_rows)::InnerIterator it(C_rows, rate + k); it; ++it)
        entries.emplace_back(tb.theta + k, q_at(static_cast<int>(it.col())), it.value());
    }
  }
  C_configuration.resize(m.n_theta_q, n_q);
  C_configuration.setFromTriplets(entries.begin(), entries.end());
}

std::vector<::Eigen::Matrix3d> SimbodyTwin::Impl::rotations(const SimTK::Vector& sq) const {
  std::vector<::Eigen::Matrix3d> out;
  for (const Rotated& r : rotated)
    out.push_back(::Eigen::Quaterniond(sq[r.quat], sq[r.quat + 1], sq[r.quat + 2], sq[r.quat + 3])
                      .normalized()
                      .toRotationMatrix());
  return out;
}

VecX SimbodyTwin::Impl::gather(const SimTK::Vector& f_u,
                               const std::vector<::Eigen::Matrix3d>& R) const {  // Pᵀ f_u
  VecX f(model.n_theta());
  for (int j = 0; j < model.n_theta(); ++j) f[j] = f_u[theta_u[j]];
  for (std::size_t i = 0; i < rotated.size(); ++i)
    f.segment<3>(rotated[i].rate) = R[i].transpose() * f.segment<3>(rotated[i].rate);
  return f;
}

SimTK::Vector SimbodyTwin::Impl::scatter(const VecX& x,
                                         const std::vector<::Eigen::Matrix3d>& R) const {  // P x
  SimTK::Vector out(state.getNU(), 0.0);
  if (rotated.empty()) {
    for (int j = 0; j < model.n_theta(); ++j) out[theta_u[j]] = x[j];
    return out;
  }
  VecX y = x;
  for (std::size_t i = 0; i < rotated.size(); ++i)
    y.segment<3>(rotated[i].rate) = R[i] * x.segment<3>(rotated[i].rate);
  for (int j = 0; j < model.n_theta(); ++j) out[theta_u[j]] = y[j];
  return out;
}

VecX SimbodyTwin::Impl::reduce(const SimTK::Vector& f_theta) const {  // Cᵀ Pᵀ f_u
  return model.C.transpose() * gather(f_theta, rot);
}

SimTK::Vector SimbodyTwin::Impl::expand(const VecX& x) const {  // P C x on Simbody's u layout
  return scatter(model.C * x, rot);
}

const VecX& SimbodyTwin::Impl::rest() {  // q̇ = 0, sized by the first call
  if (bench_rest.size() != model.n()) bench_rest = VecX::Zero(model.n());
  return bench_rest;
}

void SimbodyTwin::Impl::set_unit_rates(int b, int c) {
  SimTK::Vector& su = state.updU();
  for (int j = 0; j < model.n_theta(); ++j) su[theta_u[j]] = 0;
  for (const int col : {b, c})
    if (col >= 0)
      for (SpMatX::InnerIterator it(model.C, col); it; ++it) su[theta_u[it.row()]] += it.value();
}

void SimbodyTwin::Impl::set_state(const VecX& q, const VecX& qd, SimTK::Stage stage,
                                  bool fit_rods) {
  SimTK::Vector& sq = state.updQ();
  SimTK::Vector& su = state.updU();
  if (model.closed_loop() || !rotated.empty()) {
    if (model.closed_loop())  // θ = g(q), θ̇ = G q̇, then the rods between their ends
      loops::joint_state(model, q, qd, loop_theta, loop_theta_dot);
    else {  // a ball or free joint: θ = C_q q + θ0_q, θ̇ = C q̇
      loop_theta = C_configuration * q + theta0_configuration;
      loop_theta_dot = model.C * qd;
    }
    for (std::size_t i = 0; i < theta_q.size(); ++i) sq[theta_q[i]] = loop_theta[i];
    rot = rotations(sq);
    su = scatter(loop_theta_dot, rot);  // u = P θ̇
    for (std::size_t i = 0; i < rotated.size(); ++i) {
      if (!rotated[i].free_linear) continue;  // Ṗ θ̇ = R (ω × v) on a free joint's v
      const int r = rotated[i].rate;
      const ::Eigen::Vector3d d =
          rot[i] * loop_theta_dot.segment<3>(r + 3).cross(loop_theta_dot.segment<3>(r));
      for (int k = 0; k < 3; ++k) pdot_v[theta_u[r + k]] = d[k];
    }
    if (model.closed_loop() && fit_rods) loops::fit_rods(system, state, model, mobod, rods);
    system.realize(state, stage);
    return;
  }
  for (int j = 0; j < model.n_theta(); ++j) {
    double theta = model.theta0[j], theta_dot = 0;
    for (decltype(C_rows)::InnerIterator it(C_rows, j); it; ++it) {
      theta += it.value() * q[it.col()];
      theta_dot += it.value() * qd[it.col()];
    }
    sq[theta_q[j]] = theta;
    su[theta_u[j]] = theta_dot;
  }
  system.realize(state, stage);
}

TwinSample SimbodyTwin::Impl::sample(const SimTK::State& st) const {
  system.realize(st, SimTK::Stage::Dynamics);
  TwinSample out;
  out.t = st.getTime();
  out.theta.resize(static_cast<int>(theta_q.size()));
  for (std::size_t i = 0; i < theta_q.size(); ++i) out.theta[i] = st.getQ()[theta_q[i]];
  out.theta_dot = gather(st.getU(), rotations(st.getQ()));
  out.energy = system.calcEnergy(st);
  return out;
}

}  // namespace femdyn::validation
