#include "core/workspace/mass_solver.hpp"

#include <cholmod.h>

#include <algorithm>
#include <stdexcept>

#include "core/workspace/mass_pattern.hpp"

namespace femdyn {

// CHOLMOD is driven directly (not through Eigen's wrapper) so that, after the first call, a
// factorisation and a solve reuse every buffer: the sparse M^s (pattern fixed, values
// overwritten), the factor L, and the solve's X, Y, E workspaces (cholmod_solve2). The
// fill-reducing order comes from the Model (found once at compile); each solver stores
// A = P M^s Pᵀ in that order and lets CHOLMOD lay out its own L for it (natural ordering).
struct MassSolver::Impl {
  Eigen::LLT<MatX> dense;
  std::vector<std::pair<int, int>> entries;  // M^s (row, col) of each stored value of A
  cholmod_common common;
  cholmod_sparse* A = nullptr;  // upper triangle of P M^s Pᵀ (stype 1)
  cholmod_factor* L = nullptr;
  cholmod_dense *X = nullptr, *Y = nullptr, *E = nullptr;
  cholmod_dense B;        // header over b
  VecX b;                 // the right-hand side in CHOLMOD's order
  std::vector<int> perm;  // position k of the factorised matrix holds coordinate perm[k]
  bool started = false;

  ~Impl() {
    if (!started) return;
    cholmod_free_dense(&X, &common);
    cholmod_free_dense(&Y, &common);
    cholmod_free_dense(&E, &common);
    cholmod_free_factor(&L, &common);
    cholmod_free_sparse(&A, &common);
    cholmod_finish(&common);
  }
};

MassSolver::MassSolver(const Model& model) : MassSolver(model, model.mass_pattern.solver) {}

MassSolver::MassSolver(const Model& model, SolverKind kind)
    : kind_(kind), names_(model.coordinate_names), impl_(std::make_unique<Impl>()) {
  const int n = model.n();
  if (kind_ == SolverKind::Tree) {
    lambda_ = model.mass_pattern.coordinate_parent;
    if (static_cast<int>(lambda_.size()) != n)
      throw std::logic_error("MassSolver: the pattern of M^s is not a tree");
  }
  if (kind_ == SolverKind::Sparse) {
    Impl& s = *impl_;
    const Pattern pattern = coordinate_pattern(model);
    s.perm = model.mass_pattern.sparse_order;
    if (static_cast<int>(s.perm.size()) != n) s.perm = fill_reducing_order(pattern);  // forced
    cholmod_start(&s.common);
    s.started = true;
    s.common.print = 0;  // failures are reported as a Status, not printed
    s.common.supernodal = CHOLMOD_SIMPLICIAL;
    s.common.final_asis = 1;  // keep L as factorised: no per-call repacking
    s.common.final_pack = 0;
    s.common.final_monotonic = 0;
    // A = P M^s Pᵀ stored once in that order, analysed with the natural ordering, so that
    // factorize and solve need no permuted copies (which CHOLMOD would allocate per call).
    const auto e = ordered_upper_pattern(pattern, s.perm);
    s.A = pattern_matrix(n, e, &s.common);
    for (const auto& [r, c] : e) s.entries.emplace_back(s.perm[r], s.perm[c]);
    s.common.nmethods = 1;
    s.common.method[0].ordering = CHOLMOD_NATURAL;
    s.common.postorder = false;
    s.L = cholmod_analyze(s.A, &s.common);
    if (!s.L) throw std::bad_alloc();
    s.B = cholmod_dense{};
    s.B.nrow = s.B.d = static_cast<std::size_t>(n);
    s.B.ncol = 1;
    s.B.nzmax = static_cast<std::size_t>(n);
    s.B.xtype = CHOLMOD_REAL;
    s.B.dtype = CHOLMOD_DOUBLE;
    s.b = VecX::Zero(n);
    s.B.x = s.b.data();
  }
}

MassSolver::~MassSolver() = default;
MassSolver::MassSolver(MassSolver&&) noexcept = default;
MassSolver& MassSolver::operator=(MassSolver&&) noexcept = default;

Status MassSolver::factorize(const MatX& Ms) {
  const Eigen::Index n = Ms.rows();
  if (!Ms.allFinite()) return {false, "the mass matrix M^s has NaN or Inf entries", -1, true};
  const double scale = n > 0 ? Ms.diagonal().cwiseAbs().maxCoeff() : 0.0;
  // A coordinate that moves no inertia has a zero row and column in M^s.
  for (Eigen::Index a = 0; a < n; ++a)
    if (!(Ms(a, a) > 1e-13 * scale))
      return negligible_inertia(names_.at(a), static_cast<int>(a), Ms(a, a), scale);
  if (kind_ == SolverKind::Tree) return factorize_tree(Ms);
  if (kind_ == SolverKind::Dense) {
    impl_->dense.compute(Ms);
    if (impl_->dense.info() != Eigen::Success)
      return {false, "the mass matrix M^s is not positive definite"};
    const auto& L = impl_->dense.matrixLLT();
    for (Eigen::Index a = 0; a < n; ++a)
      if (L(a, a) * L(a, a) < 1e-13 * Ms(a, a))
        return {false,
                "the mass matrix M^s is singular: coordinate '" + names_.at(a) +
                    "' moves no inertia independently of the coordinates before it",
                static_cast<int>(a)};
    return {};
  }
  Impl& s = *impl_;
  auto* Ax = static_cast<double*>(s.A->x);
  for (std::size_t k = 0; k < s.entries.size(); ++k)
    Ax[k] = Ms(s.entries[k].first, s.entries[k].second);
  cholmod_factorize(s.A, s.L, &s.common);
  if (s.common.status == CHOLMOD_NOT_POSDEF || s.L->minor < s.L->n)
    return {false, "the mass matrix M^s is not positive definite (CHOLMOD, at coordinate '" +
                       names_.at(s.perm.at(std::min<std::size_t>(s.L->minor, s.L->n - 1))) + "')"};
  if (s.common.status < CHOLMOD_OK) return {false, "CHOLMOD failed to factorize M^s"};
  return {};
}

// M^s = Lᵀ D L over the coordinate tree, leaves first (Featherstone's LTDL): for a = n−1 … 0,
//   for each ancestor i of a:  L(a, i) = H(a, i) / D(a),
//                              H(i, j) −= L(a, i) H(a, j) for j = i and its ancestors,
// with D(a) = H(a, a) once every coordinate beyond a is eliminated. Only the chain entries
// are read or written: the pattern has no fill. Column a of the upper triangle is stored as
// its chain, LD[chain_start[a] + t] for the t-th of a, λ(a), λ(λ(a)), …; the chain of an
// ancestor i at position t is the tail of a's chain from t, so the update is contiguous.
Status MassSolver::factorize_tree(const MatX& Ms) {
  const auto n = static_cast<int>(lambda_.size());
  if (chain_start_.empty()) {  // first use only: Σ (depth + 1) entries
    chain_start_.assign(n + 1, 0);
    for (int a = 0; a < n; ++a) {
      int length = 0;
      for (int b = a; b >= 0; b = lambda_[b]) ++length;
      chain_start_[a + 1] = chain_start_[a] + length;
    }
    LD_ = VecX::Zero(chain_start_[n]);
  }
  for (int a = 0; a < n; ++a) {
    double* H = LD_.data() + chain_start_[a];
    for (int b = a, t = 0; b >= 0; b = lambda_[b], ++t) H[t] = Ms(b, a);
  }
  for (int a = n - 1; a >= 0; --a) {
    double* Ha = LD_.data() + chain_start_[a];
    const double d = Ha[0];
    if (!(d > 1e-13 * Ms(a, a)))
      return {false,
              "the mass matrix M^s is singular: coordinate '" + names_.at(a) +
                  "' moves no inertia independently of the coordinates beyond it",
              a};
    for (int i = lambda_[a], t = 1; i >= 0; i = lambda_[i], ++t) {
      const double l = Ha[t] / d;
      double* Hi = LD_.data() + chain_start_[i];
      const int length = chain_start_[i + 1] - chain_start_[i];
      for (int u = 0; u < length; ++u) Hi[u] -= l * Ha[t + u];
      Ha[t] = l;
    }
  }
  return {};
}

void MassSolver::solve_in_place(VecX& x) const {
  if (kind_ == SolverKind::Tree) {  // Lᵀ D L x = y: Lᵀ z = y, D w = z, L x = w
    const auto n = static_cast<int>(lambda_.size());
    for (int a = n - 1; a >= 0; --a) {
      const double* L = LD_.data() + chain_start_[a];
      for (int i = lambda_[a], t = 1; i >= 0; i = lambda_[i], ++t) x[i] -= L[t] * x[a];
    }
    for (int a = 0; a < n; ++a) x[a] /= LD_[chain_start_[a]];
    for (int a = 0; a < n; ++a) {
      const double* L = LD_.data() + chain_start_[a];
      for (int i = lambda_[a], t = 1; i >= 0; i = lambda_[i], ++t) x[a] -= L[t] * x[i];
    }
    return;
  }
  if (kind_ == SolverKind::Dense) {
    impl_->dense.solveInPlace(x);
    return;
  }
  Impl& s = *impl_;
  const auto n = static_cast<Eigen::Index>(s.perm.size());
  for (Eigen::Index k = 0; k < n; ++k) s.b[k] = x[s.perm[k]];
  cholmod_solve2(CHOLMOD_A, s.L, &s.B, nullptr, &s.X, nullptr, &s.Y, &s.E, &s.common);
  const auto* X = static_cast<const double*>(s.X->x);
  for (Eigen::Index k = 0; k < n; ++k) x[s.perm[k]] = X[k];
}

void MassSolver::solve(const VecX& y, VecX& x) const {
  x = y;
  solve_in_place(x);
}

}  // namespace femdyn
