#include "core/kinematics/sampling.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "core/joints/kernel.hpp"

namespace femdyn {

namespace {

// One coordinate of a one-coordinate joint (or of none: ±π).
double random_within_limits(const Joint* joint, std::mt19937& rng) {
  // ±π for a revolute joint, ±0.5 m for a prismatic one, narrowed to the joint's limits; a
  // range that the limits exclude entirely is the limits' first 2π (or 1 m), never wider,
  // so that huge limits (±1e308) never give a huge or infinite draw.
  const double half = joint ? random_half_range(*joint) : std::numbers::pi;
  double lo = -half, hi = half;
  if (joint) {
    lo = std::max(lo, joint->lower);
    hi = std::min(hi, joint->upper);
    if (lo > hi) {
      lo = std::isfinite(joint->lower) ? joint->lower : joint->upper - 2 * half;
      hi = std::min(joint->upper, lo + 2 * half);
    }
  }
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// q joint by joint over the coordinate joints: a one-coordinate joint's entry by `one`, any
// other's nq entries by `many`.
template <class One, class Many>
VecX per_joint(const Model& m, One&& one, Many&& many) {
  VecX q(m.n_q());
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (J.nq == 1)
      q[c.q] = one(J);
    else
      many(J, q.data() + c.q);
  }
  return q;
}

}  // namespace

bool flat_model(const Model& m) {
  return std::all_of(m.bodies.begin(), m.bodies.end(),
                     [](const Body& b) { return is_flat(b.joint); });
}

VecX reference_posture(const Model& m) {
  return per_joint(
      m, [](const Joint& J) { return std::clamp(0.0, J.lower, J.upper); },
      [](const Joint& J, double* q) { neutral_configuration(J, q); });
}

VecX random_posture(const Model& m, std::mt19937& rng) {
  return per_joint(
      m, [&](const Joint& J) { return random_within_limits(&J, rng); },
      [&](const Joint& J, double* q) { random_configuration(J, rng, q); });
}

VecX neutral_posture(const Model& m) {
  return per_joint(
      m, [](const Joint& J) { return J.initial; },
      [](const Joint& J, double* q) { neutral_configuration(J, q); });
}

VecX integrate_posture(const Model& m, const VecX& q, const VecX& xi) {
  if (flat_model(m)) return q + xi;
  VecX out(m.n_q());
  for (const CoordinateJoint& c : m.coordinate_joints)
    integrate_configuration(m.bodies[c.body].joint, q.data() + c.q, xi.data() + c.v,
                            out.data() + c.q);
  return out;
}

VecX chart_rates(const Model& m, const VecX& q, const VecX& xi, const VecX& v) {
  if (flat_model(m)) return v;
  VecX out(m.n());
  for (const CoordinateJoint& c : m.coordinate_joints)
    chart_rate(m.bodies[c.body].joint, q.data() + c.q, xi.data() + c.v, v.data() + c.v,
               out.data() + c.v);
  return out;
}

MatX chart_rate_jacobian(const Model& m, const VecX& v) {
  MatX A = MatX::Zero(m.n(), m.n());
  if (flat_model(m)) return A;
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    std::array<double, 36> block{};  // (nv × nv, row-major)
    chart_rate_jacobian(J, v.data() + c.v, block.data());
    A.block(c.v, c.v, J.nv, J.nv) = Eigen::Map<const RowMajor>(block.data(), J.nv, J.nv);
  }
  return A;
}

std::string normalize_quaternions(const Model& m, VecX& q) {
  for (const CoordinateJoint& c : m.coordinate_joints)
    if (const Joint& J = m.bodies[c.body].joint; !is_flat(J)) {
      auto quat = q.segment<4>(c.q + J.nq - 4);  // (the quaternion is last)
      const double norm = quat.norm();
      if (!(std::abs(norm - 1) <= 1e-6))
        return "the quaternion of joint '" + J.name + "' has norm " + std::to_string(norm) +
               ", expected 1";
      // Within 4 ε of 1 it is unit to round-off and stays as it is, so that normalising twice
      // (a door reading what another door normalised) changes no bit.
      if (std::abs(norm - 1) > 4 * std::numeric_limits<double>::epsilon()) quat /= norm;
    }
  return "";
}

VecX random_uniform(int n, double scale, std::mt19937& rng) {
  VecX x(n);
  std::uniform_real_distribution<double> d(-scale, scale);
  for (int i = 0; i < n; ++i) x[i] = d(rng);
  return x;
}

VecX random_rates(const Model& m, double scale, std::mt19937& rng) {
  VecX v = random_uniform(m.n(), scale, rng);
  for (const CoordinateJoint& c : m.coordinate_joints) {
    const Joint& J = m.bodies[c.body].joint;
    if (J.sample_range > 0) v[c.v] *= J.sample_range / type_random_half_range(J.type);
  }
  return v;
}

}  // namespace femdyn
