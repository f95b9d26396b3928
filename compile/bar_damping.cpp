#include "compile/bar_damping.hpp"

#include <Eigen/Eigenvalues>
#include <map>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {
namespace {

bool damped(const BarSpec& bar) { return bar.mass_proportional > 0 || !bar.modal.empty(); }

// The bar's elastic rates as coordinates of q̇ (each joint a coordinate of its own).
std::vector<int> bar_rates(const BarSpec& bar, const Model& m) {
  std::map<std::string, int> coordinate;
  for (int k = 0; k < m.n(); ++k) coordinate.emplace(m.coordinate_names[k], k);
  std::vector<int> e;
  for (const std::string& joint : bar.joints) {
    const auto it = coordinate.find(joint);
    if (it == coordinate.end() || !m.identity_coupling)
      throw ModelError(bar.where + "/damping",
                       "mass-proportional and modal damping need the bar's joints as coordinates "
                       "of their own (joint '" +
                           joint + "' is coupled)");
    e.push_back(it->second);
  }
  return e;
}

// D of one bar on its rates e: α M̄ + M̄ Φ diag(2 ζ_k ω_k) Φᵀ M̄.
MatX bar_damping(const BarSpec& bar, const Model& m, const MatX& Ms, const std::vector<int>& e) {
  const int ne = static_cast<int>(e.size());
  MatX M(ne, ne);
  VecX k(ne);
  for (int a = 0; a < ne; ++a) {
    k[a] = m.bodies[m.theta_joint[e[a]]].joint.stiffness;
    for (int b = 0; b < ne; ++b) M(a, b) = Ms(e[a], e[b]);
  }
  MatX D = bar.mass_proportional * M;
  if (bar.modal.empty()) return D;
  // K φ = ω² M̄ φ with Φᵀ M̄ Φ = I (Eigen's generalized solver normalises so), ascending ω.
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> modes(MatX(k.asDiagonal()), M);
  if (modes.info() != Eigen::Success)
    throw ModelError(bar.where + "/damping/modal", "the bar's modes could not be computed");
  VecX c(ne);
  for (int j = 0; j < ne; ++j) {
    const double zeta = bar.modal[std::min<std::size_t>(j, bar.modal.size() - 1)];
    c[j] = 2 * zeta * std::sqrt(std::max(0.0, modes.eigenvalues()[j]));
  }
  const MatX MPhi = M * modes.eigenvectors();
  D.noalias() += MPhi * c.asDiagonal() * MPhi.transpose();
  return D;
}

}  // namespace

void compile_bar_damping(const std::vector<BarSpec>& bars, Model& m) {
  std::vector<Eigen::Triplet<double>> entries;
  MatX Ms;
  for (const BarSpec& bar : bars) {
    if (!damped(bar)) continue;
    if (m.coupling_level)
      throw ModelError(bar.where + "/damping",
                       "mass-proportional and modal damping are not taken with a coupling law");
    const std::vector<int> e = bar_rates(bar, m);
    if (Ms.size() == 0) {  // M^s at the neutral posture, once
      Workspace ws(m);
      mass_matrix(m, ws, neutral_posture(m));
      Ms = ws.Ms;
    }
    const MatX D = bar_damping(bar, m, Ms, e);
    for (std::size_t a = 0; a < e.size(); ++a)
      for (std::size_t b = 0; b < e.size(); ++b)
        if (D(a, b) != 0) entries.emplace_back(e[a], e[b], D(a, b));
  }
  if (entries.empty()) return;
  m.rate_damping.resize(m.n(), m.n());
  m.rate_damping.setFromTriplets(entries.begin(), entries.end());
  m.has_rate_damping = true;
}

}  // namespace femdyn
