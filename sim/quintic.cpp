#include "sim/quintic.hpp"

#include <algorithm>
#include <array>

#include "core/joints/kernel.hpp"

namespace femdyn {

namespace {

// s(x) = 10x³ − 15x⁴ + 6x⁵ at x = t/T (clamped to [0, 1]), and ṡ, s̈ in time.
struct Scaling {
  double s, ds, dds;
};
Scaling scaling(double T, double t) {
  const double x = std::clamp(t / T, 0.0, 1.0);
  return {x * x * x * (10 - 15 * x + 6 * x * x), 30 * x * x * (1 - x) * (1 - x) / T,
          60 * x * (1 - x) * (1 - 2 * x) / (T * T)};
}

}  // namespace

void quintic(const Model& m, const VecX& q0, const VecX& delta, double T, double t, VecX& q,
             VecX& v, VecX& vdot) {
  const auto [s, ds, dds] = scaling(T, t);
  q.resize(m.n_q());
  v.resize(m.n());
  vdot.resize(m.n());
  std::array<double, 6> w{}, dw{}, step{};
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    for (int k = 0; k < J.nv; ++k) step[k] = s * delta[c.v + k];
    integrate_configuration(J, q0.data() + c.q, step.data(), q.data() + c.q);
    ray_rates(J, delta.data() + c.v, s, w.data(), dw.data());
    for (int k = 0; k < J.nv; ++k) {
      v[c.v + k] = ds * w[k];
      vdot[c.v + k] = dds * w[k] + ds * ds * dw[k];
    }
  }
}

VecX configuration_difference(const Model& m, const VecX& q0, const VecX& q1) {
  VecX delta(m.n());
  for (const CoordinateJoint& c : m.coordinate_joints)
    configuration_difference(m.bodies[c.body].joint, q0.data() + c.q, q1.data() + c.q,
                             delta.data() + c.v);
  return delta;
}

}  // namespace femdyn
