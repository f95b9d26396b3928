#include "core/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "core/joints/kernel.hpp"

namespace femdyn {

namespace {

// Coordinate -> its joint (by name).
// (By the coordinates' names, so that compile may call it before C has its final width.)
std::vector<const Joint*> coordinate_joints(const Model& m) {
  const int n = static_cast<int>(m.coordinate_names.size());
  std::vector<const Joint*> joint_of(n, nullptr);
  std::map<std::string, int> coordinate;
  for (int a = 0; a < n; ++a) coordinate.emplace(m.coordinate_names[a], a);
  for (const Body& b : m.bodies)
    if (const auto it = coordinate.find(b.joint.name); it != coordinate.end())
      joint_of[it->second] = &b.joint;
  return joint_of;
}

}  // namespace

VecX reference_posture(const Model& m) {
  const std::vector<const Joint*> joint_of = coordinate_joints(m);
  const int n = static_cast<int>(joint_of.size());
  VecX q(n);
  for (int a = 0; a < n; ++a)
    q[a] = joint_of[a] ? std::clamp(0.0, joint_of[a]->lower, joint_of[a]->upper) : 0.0;
  return q;
}

VecX random_posture(const Model& m, std::mt19937& rng) {
  const std::vector<const Joint*> joint_of = coordinate_joints(m);
  VecX q(m.n());
  for (int a = 0; a < m.n(); ++a) {
    const Joint* joint = joint_of[a];
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
    q[a] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

VecX random_uniform(int n, double scale, std::mt19937& rng) {
  VecX x(n);
  std::uniform_real_distribution<double> d(-scale, scale);
  for (int i = 0; i < n; ++i) x[i] = d(rng);
  return x;
}

}  // namespace femdyn
