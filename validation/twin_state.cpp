// The twin's state mapping (twin_impl.hpp): femdyn's q, q̇ (and θ, θ̇) to and from Simbody's
// state, and the maps by C and Cᵀ between q and Simbody's u layout. Compiled like twin.cpp
// (C++17, without NDEBUG).
#include <Simbody.h>

#include "validation/twin_impl.hpp"
#include "validation/twin_loops.hpp"

namespace femdyn::validation {

void SimbodyTwin::Impl::finish_state() {
  using namespace SimTK;
  const TwinModel& m = model;
  state = system.realizeTopology();
  system.realizeModel(state);
  theta_q.resize(m.n_theta());
  theta_u.resize(m.n_theta());
  for (int j = 0; j < m.n_theta(); ++j) {
    theta_q[j] = mobod[m.theta_body[j]].getFirstQIndex(state);
    theta_u[j] = mobod[m.theta_body[j]].getFirstUIndex(state);
  }
  const int nu = state.getNU();
  zero_mobility = Vector(nu, 0.0);
  zero_body =
      Vector_<SpatialVec>(matter.getNumBodies(), SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0)));
}

VecX SimbodyTwin::Impl::reduce(const SimTK::Vector& f_theta) const {  // Cᵀ f_θ
  VecX f(model.n_theta());
  for (int j = 0; j < model.n_theta(); ++j) f[j] = f_theta[theta_u[j]];
  return model.C.transpose() * f;
}

SimTK::Vector SimbodyTwin::Impl::expand(const VecX& x) const {  // C x on Simbody's u layout
  SimTK::Vector out(state.getNU(), 0.0);
  const VecX y = model.C * x;
  for (int j = 0; j < model.n_theta(); ++j) out[theta_u[j]] = y[j];
  return out;
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
  if (model.closed_loop()) {  // θ = g(q), θ̇ = G q̇, then the rods between their ends
    loops::joint_state(model, q, qd, loop_theta, loop_theta_dot);
    for (int j = 0; j < model.n_theta(); ++j) {
      sq[theta_q[j]] = loop_theta[j];
      su[theta_u[j]] = loop_theta_dot[j];
    }
    if (fit_rods) loops::fit_rods(system, state, model, mobod, rods);
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
  const int nt = model.n_theta();
  TwinSample out;
  out.t = st.getTime();
  out.theta.resize(nt);
  out.theta_dot.resize(nt);
  for (int j = 0; j < nt; ++j) {
    out.theta[j] = st.getQ()[theta_q[j]];
    out.theta_dot[j] = st.getU()[theta_u[j]];
  }
  out.energy = system.calcEnergy(st);
  return out;
}

}  // namespace femdyn::validation
