// Solves M^s x = y by a Cholesky-type factorisation, chosen from the structural pattern of M^s:
//   Tree    the pattern is a tree over the coordinates (coordinate a couples with b < a only
//           along a chain b = λ(a), λ(λ(a)), …, the coordinate tree): Featherstone's sparse
//           LTDL factorisation M^s = Lᵀ D L in that order, which has no fill ("Rigid Body
//           Dynamics Algorithms" §6.5). O(Σ depth²) to factorise, O(Σ depth) to solve.
//           Trees, chains and couplings that stay within one branch.
//   Dense   LLT, any other pattern below 64 coordinates.
//   Sparse  CHOLMOD with the symbolic analysis done once, for larger patterns with fill < 0.3
//           (couplings across branches).
// Numerical failure (a singular or indefinite M^s) is a Status naming the coordinate that lost
// its pivot.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/model/model.hpp"
#include "core/workspace/status.hpp"

namespace femdyn {

class MassSolver {
 public:
  // The structural pattern of M^s: (a, b) may be non-zero iff coordinates a and b move a
  // common transition coordinate.
  explicit MassSolver(const Model& model);          // Model::mass_pattern's choice
  MassSolver(const Model& model, SolverKind kind);  // another kind (Tree needs a tree)
  ~MassSolver();
  MassSolver(MassSolver&&) noexcept;
  MassSolver& operator=(MassSolver&&) noexcept;

  SolverKind kind() const { return kind_; }
  Status factorize(const MatX& Ms);
  void solve(const VecX& y, VecX& x) const;
  void solve_in_place(VecX& x) const;  // no allocation after the first call

 private:
  struct Impl;
  Status factorize_tree(const MatX& Ms);
  SolverKind kind_;
  std::vector<std::string> names_;  // coordinate names, for messages
  std::vector<int> lambda_;         // Tree: the parent coordinate λ(a) (-1 at a root)
  std::vector<int> chain_start_;  // Tree: where column a's chain starts in LD_ (sized on first use)
  VecX LD_;                       // Tree: D(a), then L(a, b) for b = λ(a), λ(λ(a)), …
  std::unique_ptr<Impl> impl_;
};

}  // namespace femdyn
