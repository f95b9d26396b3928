#include "core/sampling.hpp"

#include <cmath>
#include <numbers>

namespace femdyn {

VecX random_posture(const Model& m, std::mt19937& rng) {
  VecX q(m.n());
  for (int a = 0; a < m.n(); ++a) {
    const Joint* joint = nullptr;
    for (const Body& b : m.bodies)
      if (b.joint.name == m.coordinate_names[a]) joint = &b.joint;
    double lo = joint && joint->type == JointType::Prismatic ? -0.5 : -std::numbers::pi;
    double hi = -lo;
    if (joint && std::isfinite(joint->lower)) lo = joint->lower;
    if (joint && std::isfinite(joint->upper)) hi = joint->upper;
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
