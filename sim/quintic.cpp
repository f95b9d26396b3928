#include "sim/quintic.hpp"

#include <algorithm>

namespace femdyn {

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
