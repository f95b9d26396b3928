#include "core/mass_solver.hpp"

#include <Eigen/CholmodSupport>
#include <algorithm>

namespace femdyn {
namespace {

// Structural pattern of M^s = Tᵀ M T: coordinates a and b couple iff some carrier (node or
// body) moves with both. A carrier on body k moves with every coordinate of a joint on the
// path from k to the root (through the coupling matrix C).
std::vector<std::vector<bool>> coordinate_pattern(const Model& model) {
  const int n = model.n(), nb = static_cast<int>(model.bodies.size());
  std::vector<std::vector<bool>> moves(nb, std::vector<bool>(n, false));  // body -> coordinates
  for (int b = 0; b < nb; ++b) {
    const Body& B = model.bodies[b];
    if (B.parent >= 0) moves[b] = moves[B.parent];
    if (B.joint.theta >= 0)
      for (int a = 0; a < n; ++a)
        if (model.C(B.joint.theta, a) != 0) moves[b][a] = true;
  }
  std::vector<std::vector<bool>> pattern(n, std::vector<bool>(n, false));
  for (int b = 0; b < nb; ++b)
    for (int a = 0; a < n; ++a)
      if (moves[b][a])
        for (int c = 0; c < n; ++c)
          if (moves[b][c]) pattern[a][c] = true;
  return pattern;
}

}  // namespace

double mass_matrix_fill(const Model& model) {
  const int n = model.n();
  if (n == 0) return 1.0;
  const auto p = coordinate_pattern(model);
  double nnz = 0;
  for (const auto& row : p) nnz += static_cast<double>(std::count(row.begin(), row.end(), true));
  return nnz / (static_cast<double>(n) * n);
}

SolverKind choose_solver(const Model& model) {
  // Dense Cholesky is faster below a few dozen coordinates whatever the fill.
  return model.n() >= 64 && mass_matrix_fill(model) < 0.3 ? SolverKind::Sparse
                                                           : SolverKind::Dense;
}

struct MassSolver::Impl {
  Eigen::LLT<MatX> dense;
  SpMat sparse_Ms;                                   // pattern fixed at construction
  std::vector<std::pair<int, int>> entries;          // (row, col) of each stored value
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> cholmod;
  bool analyzed = false;
};

MassSolver::MassSolver(const Model& model) : MassSolver(model, choose_solver(model)) {}

MassSolver::MassSolver(const Model& model, SolverKind kind)
    : kind_(kind), names_(model.coordinate_names), impl_(std::make_unique<Impl>()) {
  if (kind_ == SolverKind::Sparse) {
    const auto p = coordinate_pattern(model);
    const int n = model.n();
    std::vector<Eigen::Triplet<double>> trip;
    for (int c = 0; c < n; ++c)
      for (int r = c; r < n; ++r)
        if (p[r][c] || r == c) trip.emplace_back(r, c, 1.0);
    impl_->sparse_Ms.resize(n, n);
    impl_->sparse_Ms.setFromTriplets(trip.begin(), trip.end());
    impl_->sparse_Ms.makeCompressed();
    for (int c = 0; c < n; ++c)
      for (SpMat::InnerIterator it(impl_->sparse_Ms, c); it; ++it)
        impl_->entries.emplace_back(static_cast<int>(it.row()), c);
  }
}

MassSolver::~MassSolver() = default;
MassSolver::MassSolver(MassSolver&&) noexcept = default;
MassSolver& MassSolver::operator=(MassSolver&&) noexcept = default;

Status MassSolver::factorize(const MatX& Ms) {
  const Eigen::Index n = Ms.rows();
  if (!Ms.allFinite()) return {false, "the mass matrix M^s has NaN or Inf entries"};
  const double scale = n > 0 ? Ms.diagonal().cwiseAbs().maxCoeff() : 0.0;
  // A coordinate that moves no inertia has a zero row and column in M^s.
  for (Eigen::Index a = 0; a < n; ++a)
    if (!(Ms(a, a) > 1e-13 * scale))
      return {false, "the mass matrix M^s is singular: coordinate '" + names_.at(a) +
                         "' moves no inertia (massless chain end?)",
              static_cast<int>(a)};
  if (kind_ == SolverKind::Dense) {
    impl_->dense.compute(Ms);
    if (impl_->dense.info() != Eigen::Success)
      return {false, "the mass matrix M^s is not positive definite"};
    const auto& L = impl_->dense.matrixLLT();
    for (Eigen::Index a = 0; a < n; ++a)
      if (L(a, a) * L(a, a) < 1e-13 * Ms(a, a))
        return {false, "the mass matrix M^s is singular: coordinate '" + names_.at(a) +
                           "' moves no inertia independently of the coordinates before it",
                static_cast<int>(a)};
    return {};
  }
  double* values = impl_->sparse_Ms.valuePtr();
  for (std::size_t k = 0; k < impl_->entries.size(); ++k)
    values[k] = Ms(impl_->entries[k].first, impl_->entries[k].second);
  if (!impl_->analyzed) {
    impl_->cholmod.analyzePattern(impl_->sparse_Ms);
    impl_->analyzed = true;
  }
  impl_->cholmod.factorize(impl_->sparse_Ms);
  if (impl_->cholmod.info() != Eigen::Success)
    return {false, "the mass matrix M^s is not positive definite (CHOLMOD)"};
  return {};
}

void MassSolver::solve_in_place(VecX& x) const {
  if (kind_ == SolverKind::Dense)
    impl_->dense.solveInPlace(x);
  else
    x = impl_->cholmod.solve(x);
}

void MassSolver::solve(const VecX& y, VecX& x) const {
  if (kind_ == SolverKind::Dense)
    x = impl_->dense.solve(y);
  else
    x = impl_->cholmod.solve(y);
}

}  // namespace femdyn
