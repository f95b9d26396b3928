// The structural pattern of M^s = Tᵀ M T, from the model's tree, coupling and spanning elements
// alone: which coordinates couple, whether they couple along a tree (no fill), and CHOLMOD's
// fill-reducing order otherwise. Read by compile's choice of solver (compile/routes.hpp,
// analyse_mass_pattern) and by the MassSolver a kind is forced on (core/workspace/mass_solver.hpp).
#pragma once
#include <cholmod.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/model/model.hpp"

namespace femdyn {

// Coordinates a and b couple iff some carrier (node or body) moves with both. A carrier on
// body k moves with every coordinate of a joint on the path from k to the root (through the
// coupling matrix C). As bit rows, built in O((bodies + nnz(C)) · n / 64): moves[k] (the path's
// coordinates), sub[k] = ∪ moves over the subtree of k, and row a = ∪ sub[k] over the bodies k
// whose joint a drives.
struct Pattern {
  int n = 0;
  std::size_t words = 0;
  std::vector<std::uint64_t> bits;  // row a: words [a·words, (a+1)·words)
  bool test(int a, int c) const { return (bits[a * words + c / 64] >> (c % 64)) & 1U; }
};
Pattern coordinate_pattern(const Model& model);

// The upper triangle of M^s's pattern in the coordinate order `order`: (row, col) in the
// ordered matrix, sorted by column then row.
std::vector<std::pair<int, int>> ordered_upper_pattern(const Pattern& p,
                                                       const std::vector<int>& order);

// A CHOLMOD matrix (upper triangle stored) with the given pattern: 1 on the diagonal, 0 off it.
cholmod_sparse* pattern_matrix(int n, const std::vector<std::pair<int, int>>& e, cholmod_common* c);

// CHOLMOD's fill-reducing ordering of the pattern (its default choice among AMD and METIS).
std::vector<int> fill_reducing_order(const Pattern& p);

// Structural fill ratio of M^s (non-zeros / n²).
double mass_matrix_fill(const Model& model);

// The coordinate tree λ of M^s's pattern (λ(a) < a, -1 at a root), or nothing when the
// pattern is not a tree in coordinate order (or the model has an explicit table, whose DOF
// aliases can couple branches).
std::vector<int> coordinate_tree(const Model& model);

}  // namespace femdyn
