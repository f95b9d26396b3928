#include "core/workspace/mass_pattern.hpp"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include "core/joints/kernel.hpp"

namespace femdyn {

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

}  // namespace femdyn
