// Solves M^s x = y by Cholesky. Dense LLT for small systems; for large trees with a sparse
// M^s (branches decouple) a CHOLMOD supernodal factorisation whose symbolic analysis is done
// once. Chosen automatically from n and the structural fill of M^s; numerical failure (a
// singular or indefinite M^s) is a Status naming the first coordinate that lost its pivot.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "core/status.hpp"

namespace femdyn {

enum class SolverKind { Dense, Sparse };

class MassSolver {
 public:
  // The structural pattern of M^s: (a, b) may be non-zero iff coordinates a and b move a
  // common transition coordinate.
  MassSolver(const Model& model, SolverKind kind);
  explicit MassSolver(const Model& model);  // automatic choice
  ~MassSolver();
  MassSolver(MassSolver&&) noexcept;
  MassSolver& operator=(MassSolver&&) noexcept;

  SolverKind kind() const { return kind_; }
  Status factorize(const MatX& Ms);
  void solve(const VecX& y, VecX& x) const;
  void solve_in_place(VecX& x) const;  // no allocation after the first call

 private:
  struct Impl;
  SolverKind kind_;
  std::vector<std::string> names_;  // coordinate names, for messages
  std::unique_ptr<Impl> impl_;
};

// Structural fill ratio of M^s (non-zeros / n²) and whether the sparse solver is chosen.
double mass_matrix_fill(const Model& model);
SolverKind choose_solver(const Model& model);

}  // namespace femdyn
