#include "core/model/coupling_level.hpp"

#include <algorithm>

namespace femdyn {

CouplingLevelState::CouplingLevelState(const CouplingLevel& level)
    : theta(VecX::Zero(level.n_theta_q)),
      theta_dot(VecX::Zero(level.n_theta)),
      theta_dot_y(VecX::Zero(level.n_theta)),
      gamma(VecX::Zero(level.n_theta)),
      G(MatX::Zero(level.n_theta, level.n)),
      x(level.largest_arity),
      df(level.largest_arity),
      d2f(level.largest_arity * level.largest_arity),
      f_theta(VecX::Zero(level.n_theta)),
      theta_ddot(VecX::Zero(level.n_theta)) {
  // The pattern of G: a coordinate's own joint follows that coordinate alone; a coupled joint,
  // in dependency order, the union of its sources' patterns.
  std::vector<std::vector<int>> rows(level.n_theta);
  for (int a = 0; a < level.n; ++a) rows[level.coordinate_theta[a]] = {a};
  for (const CoupledJoint& j : level.coupled) {
    std::vector<int>& row = rows[j.theta];
    row.clear();
    for (int s : j.sources) row.insert(row.end(), rows[s].begin(), rows[s].end());
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  g_begin.assign(1, 0);
  for (const std::vector<int>& row : rows) {
    g_col.insert(g_col.end(), row.begin(), row.end());
    g_begin.push_back(static_cast<int>(g_col.size()));
  }
}

bool evaluate_level(const CouplingLevel& level, const VecX& q, const VecX& x, const VecX& y,
                    CouplingLevelState& s, bool hessian) {
  if (hessian && s.H.size() != static_cast<std::size_t>(level.n_theta))
    s.H.assign(level.n_theta, MatX::Zero(level.n, level.n));  // first request only
  s.failed = -1;
  for (std::size_t i = 0; i < level.configuration_theta.size(); ++i)
    s.theta[level.configuration_theta[i]] = q[i];  // the coordinates' own joints: θ = q
  for (int a = 0; a < level.n; ++a) {              // and their rates: θ̇_t = x_a
    const int t = level.coordinate_theta[a];
    s.theta_dot[t] = x[a];
    s.theta_dot_y[t] = y[a];
    s.gamma[t] = 0;
    s.G.row(t).setZero();
    s.G(t, a) = 1;
    if (hessian) s.H[t].setZero();
  }
  for (std::size_t c = 0; c < level.coupled.size(); ++c) {
    const CoupledJoint& j = level.coupled[c];
    const int k = static_cast<int>(j.sources.size());
    for (int i = 0; i < k; ++i) s.x[i] = s.theta[level.theta_q[j.sources[i]]];
    double f = 0;
    if (!j.law->evaluate({s.x.data(), static_cast<std::size_t>(k)}, f,
                         {s.df.data(), static_cast<std::size_t>(k)},
                         {s.d2f.data(), static_cast<std::size_t>(k * k)})) {
      s.failed = static_cast<int>(c);
      return false;
    }
    const int t = j.theta;
    s.theta[level.theta_q[t]] = f;
    s.G.row(t).setZero();
    s.theta_dot[t] = s.theta_dot_y[t] = s.gamma[t] = 0;
    if (hessian) s.H[t].setZero();
    for (int i = 0; i < k; ++i) {
      const int si = j.sources[i];
      const double fi = s.df[i];
      s.G.row(t) += fi * s.G.row(si);
      s.theta_dot[t] += fi * s.theta_dot[si];
      s.theta_dot_y[t] += fi * s.theta_dot_y[si];
      s.gamma[t] += fi * s.gamma[si];
      if (hessian) s.H[t] += fi * s.H[si];
      for (int l = 0; l < k; ++l) {
        const int sl = j.sources[l];
        const double fil = s.d2f[i * k + l];
        if (fil == 0) continue;
        s.gamma[t] += fil * s.theta_dot[si] * s.theta_dot_y[sl];
        if (hessian) s.H[t].noalias() += fil * s.G.row(si).transpose() * s.G.row(sl);
      }
    }
  }
  return true;
}

}  // namespace femdyn
