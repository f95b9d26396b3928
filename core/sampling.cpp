#include "core/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>

namespace femdyn {

VecX random_posture(const Model& m, std::mt19937& rng) {
  std::vector<const Joint*> joint_of(m.n(), nullptr);  // coordinate -> its joint (by name)
  std::map<std::string, int> coordinate;
  for (int a = 0; a < m.n(); ++a) coordinate.emplace(m.coordinate_names[a], a);
  for (const Body& b : m.bodies)
    if (const auto it = coordinate.find(b.joint.name); it != coordinate.end())
      joint_of[it->second] = &b.joint;
  VecX q(m.n());
  for (int a = 0; a < m.n(); ++a) {
    const Joint* joint = joint_of[a];
    // ±π for a revolute joint, ±0.5 m for a prismatic one, narrowed to the joint's limits; a
    // range that the limits exclude entirely is the limits' first 2π (or 1 m), never wider,
    // so that huge limits (±1e308) never give a huge or infinite draw.
    const double half = joint && joint->type == JointType::Prismatic ? 0.5 : std::numbers::pi;
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
