#include "core/workspace/mass_solver.hpp"

#include <cholmod.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <stdexcept>

#include "core/joints/kernel.hpp"

namespace femdyn {
namespace {

// Structural pattern of M^s = Tᵀ M T: coordinates a and b couple iff some carrier (node or
// body) moves with both. A carrier on body k moves with every coordinate of a joint on the
// path from k to the root (through the coupling matrix C). As bit rows, built in
// O((bodies + nnz(C)) · n / 64): moves[k] (the path's coordinates), sub[k] = ∪ moves over the
// subtree of k, and row a = ∪ sub[k] over the bodies k whose joint a drives.
struct Pattern {
  int n = 0;
  std::size_t words = 0;
  std::vector<std::uint64_t> bits;  // row a: words [a·words, (a+1)·words)
  bool test(int a, int c) const { return (bits[a * words + c / 64] >> (c % 64)) & 1U; }
};

Pattern coordinate_pattern(const Model& model) {
  const int n = model.n(), nb = static_cast<int>(model.bodies.size());
  const std::size_t w = (static_cast<std::size_t>(n) + 63) / 64;
  std::vector<std::uint64_t> moves(nb * w, 0), sub;
  const auto row = [w](std::vector<std::uint64_t>& v, int k) { return v.data() + k * w; };
  for (int b = 0; b < nb; ++b) {
    const Body& B = model.bodies[b];
    if (B.parent >= 0) std::copy_n(row(moves, B.parent), w, row(moves, b));
    for (int t = B.joint.idx_v; t < B.joint.idx_v + B.joint.nv; ++t)
      for (SpRowMat::InnerIterator it(model.C_sparse, t); it; ++it)
        row(moves, b)[it.col() / 64] |= std::uint64_t{1} << (it.col() % 64);
  }
  sub = moves;
  for (int b = nb - 1; b >= 0; --b)
    if (model.bodies[b].parent >= 0)
      for (std::size_t k = 0; k < w; ++k) row(sub, model.bodies[b].parent)[k] |= row(sub, b)[k];
  Pattern p{n, w, std::vector<std::uint64_t>(static_cast<std::size_t>(n) * w, 0)};
  for (int b = 0; b < nb; ++b) {
    const Joint& J = model.bodies[b].joint;
    for (int t = J.idx_v; t < J.idx_v + J.nv; ++t)
      for (SpRowMat::InnerIterator it(model.C_sparse, t); it; ++it)
        for (std::size_t k = 0; k < w; ++k) p.bits[it.col() * w + k] |= row(sub, b)[k];
  }
  // An element spanning bodies couples every coordinate that moves one of its nodes with every
  // other (its nodes may lie on different branches).
  std::vector<std::uint64_t> span(w);
  for (const ElementEntry& e : model.elements) {
    if (!e.spans) continue;
    std::fill(span.begin(), span.end(), 0);
    for (const int b : e.node_body)
      if (b >= 0)
        for (std::size_t k = 0; k < w; ++k) span[k] |= row(moves, b)[k];
    for (int a = 0; a < n; ++a)
      if (span[a / 64] >> (a % 64) & 1)
        for (std::size_t k = 0; k < w; ++k) p.bits[a * w + k] |= span[k];
  }
  return p;
}

// The upper triangle of M^s's pattern in the coordinate order `order`: (row, col) in the
// ordered matrix, sorted by column then row.
std::vector<std::pair<int, int>> ordered_upper_pattern(const Pattern& p,
                                                       const std::vector<int>& order) {
  const int n = p.n;
  std::vector<int> where(n);  // coordinate -> position in `order`
  for (int k = 0; k < n; ++k) where[order[k]] = k;
  std::vector<std::pair<int, int>> e;
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r)
      if ((p.test(r, c) || r == c) && where[r] <= where[c]) e.emplace_back(where[r], where[c]);
  std::sort(e.begin(), e.end(), [](auto x, auto y) {
    return std::pair(x.second, x.first) < std::pair(y.second, y.first);
  });
  return e;
}

// A CHOLMOD matrix (upper triangle stored) with the given pattern: 1 on the diagonal, 0 off it.
cholmod_sparse* pattern_matrix(int n, const std::vector<std::pair<int, int>>& e,
                               cholmod_common* c) {
  cholmod_sparse* A =
      cholmod_allocate_sparse(n, n, e.size(), 1, 1, /*stype: upper*/ 1, CHOLMOD_REAL, c);
  if (!A) throw std::bad_alloc();
  auto* Ap = static_cast<int*>(A->p);
  auto* Ai = static_cast<int*>(A->i);
  auto* Ax = static_cast<double*>(A->x);
  for (std::size_t k = 0; k < e.size(); ++k) {
    Ai[k] = e[k].first;
    Ax[k] = e[k].first == e[k].second ? 1.0 : 0.0;
  }
  for (int col = 0, k = 0; col <= n; ++col) {
    while (k < static_cast<int>(e.size()) && e[k].second < col) ++k;
    Ap[col] = k;
  }
  return A;
}

// CHOLMOD's fill-reducing ordering of the pattern (its default choice among AMD and METIS).
std::vector<int> fill_reducing_order(const Pattern& p) {
  cholmod_common c;
  cholmod_start(&c);
  c.print = 0;
  std::vector<int> identity(p.n);
  for (int k = 0; k < p.n; ++k) identity[k] = k;
  cholmod_sparse* A = pattern_matrix(p.n, ordered_upper_pattern(p, identity), &c);
  cholmod_factor* L = cholmod_analyze(A, &c);
  std::vector<int> order;
  if (L) order.assign(static_cast<int*>(L->Perm), static_cast<int*>(L->Perm) + p.n);
  cholmod_free_factor(&L, &c);
  cholmod_free_sparse(&A, &c);
  cholmod_finish(&c);
  if (order.empty()) throw std::bad_alloc();
  return order;
}

}  // namespace

double mass_matrix_fill(const Model& model) {
  const int n = model.n();
  if (n == 0) return 1.0;
  const Pattern p = coordinate_pattern(model);
  double nnz = 0;
  for (const std::uint64_t word : p.bits) nnz += std::popcount(word);
  return nnz / (static_cast<double>(n) * n);
}

std::vector<int> coordinate_tree(const Model& model) {
  const int n = model.n();
  if (model.explicit_table || n == 0) return {};
  // Without couplings or spanning elements q = θ̇ and M^s is the tree's: λ is compile's, over the
  // joints' rates (Model::rate_parent).
  const bool spans = std::any_of(model.elements.begin(), model.elements.end(),
                                 [](const ElementEntry& e) { return e.spans; });
  if (model.identity_coupling && !spans) return model.rate_parent;
  const Pattern p = coordinate_pattern(model);
  std::vector<int> lambda(n, -1);
  for (int a = 0; a < n; ++a) {
    int below = 0;  // coordinates b < a coupled with a
    for (int b = 0; b < a; ++b)
      if (p.test(a, b)) ++below, lambda[a] = b;
    // A tree iff those are exactly the chain λ(a), λ(λ(a)), … (each coupled with a).
    int chain = 0;
    for (int b = lambda[a]; b >= 0; b = lambda[b], ++chain)
      if (!p.test(a, b)) return {};
    if (chain != below) return {};
  }
  return lambda;
}

void analyse_mass_pattern(Model& model) {
  MassPattern& mp = model.mass_pattern;
  mp = MassPattern{};
  mp.coordinate_parent = coordinate_tree(model);
  if (!mp.coordinate_parent.empty()) {
    mp.solver = SolverKind::Tree;  // no fill, at any size
    return;
  }
  // Dense Cholesky is faster below a few dozen coordinates whatever the fill.
  if (model.n() < 64 || mass_matrix_fill(model) >= 0.3) return;
  mp.solver = SolverKind::Sparse;
  mp.sparse_order = fill_reducing_order(coordinate_pattern(model));
}

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
