// (M^s)⁻¹ and the products ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂· of the analytic derivatives
// (core/derivatives/derivatives.hpp), on the factorisation the forward dynamics leaves in the
// Workspace.
//
// On the articulated route with the rates numbered depth first (a subtree's rates contiguous,
// from its joint's first), (M^s)⁻¹ is formed in one O(n · bodies) sweep (Carpentier,
// "Analytical inverse of the joint space inertia matrix", 2018): articulated_solve applied to all
// n unit vectors at once. Leaves to root, the unit vectors of a subtree's rates are the only ones
// with articulated forces below it, so one 6 × n matrix P holds every body's (world axes about
// the origin: no transform between bodies), and on the subtree's columns
//   u = e − Sᵀ P,   P += U D⁻¹ u;
// root to leaves, on the columns from the joint's first rate on (the upper triangle; the lower by
// symmetry), with a the accelerations of the parent,
//   x = D⁻¹ u − D⁻¹ Uᵀ a,   a_body = a + S x.
// (M^s)⁻¹ is block diagonal: M^s(c, m) ≠ 0 only if one of c, m is on the other's path to the
// root, so rates couple only if they share a moving ancestor-or-self. Each block is the subtree
// of a moving body none of whose ancestors moves, and only the blocks are formed.
//
// A column m of ∂τ/∂· is non-zero only on the rates of its body's ancestors and subtree (a pair
// couples only along one path to the root): runs of consecutive rates. Up to n = 96,
// −(M^s)⁻¹ ∂τ/∂· is formed as each run times its block of (M^s)⁻¹; above, by the factorisation
// eight columns at a time (articulated_solve's steps on 6 × 8 forces and accelerations per body).
// Off the articulated route, (M^s)⁻¹ by n column solves and the products dense (up to n = 96).
#pragma once
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct DerivativeWorkspace;

// Rates [first, first + count) where a column of ∂τ/∂· can be non-zero, all in one diagonal
// block of (M^s)⁻¹: their part of the product −(M^s)⁻¹ ∂τ/∂· lands in rows
// [block_first, block_end) only.
struct RowRun {
  int first, count, block_first, block_end;
};

// Columns [first, first + count) of ∂τ/∂·, whose non-zero rows are the same runs of rates
// runs[run_begin .. run_end).
struct ColumnGroup {
  int first, count, run_begin, run_end;
};

// The sweep's layout and buffers, planned once for a model (no allocation per call).
struct InverseMassSweep {
  bool applies = false;  // articulated route, rates numbered depth first
  // Per body: its subtree's first rate and count, the slot of its accelerations' block (a body
  // that is its parent's last child reuses its parent's), the rates [block_first, block_end) of
  // its block of (M^s)⁻¹ (a body outside every block: its subtree's).
  std::vector<int> sub_first, sub_count, slot, block_first, block_end;
  Eigen::Matrix<double, 6, Eigen::Dynamic> P, A;  // the forces (6 × n), the slots' accelerations
  MatX rows;  // a joint's rows of (M^s)⁻¹ while they are formed (n × 6)
  // The rows where a column of ∂τ/∂· can be non-zero, as runs within one block; columns with the
  // same runs side by side are one group.
  std::vector<RowRun> runs;
  std::vector<ColumnGroup> groups;
  // Above n = 96: per body a 6 × 8 force and acceleration, and the eight columns.
  std::vector<Eigen::Matrix<double, 6, 8>> chunk_force, chunk_acceleration;
  Eigen::Matrix<double, Eigen::Dynamic, 8, Eigen::RowMajor> chunk;

  void plan(const Model& model);  // sets applies and, if so, the layout
};

// (M^s)⁻¹ into d.Minv by the factorisation the last forward dynamics (or constrained forward
// dynamics) left in ws: the O(n · bodies) sweep on the articulated route, else n column solves.
void inverse_mass_matrix(const Model& model, Workspace& ws, DerivativeWorkspace& d);

// Y = −(M^s)⁻¹ K for K = ∂τ/∂· (n × n), with the d.Minv of inverse_mass_matrix.
void minus_inverse_mass_times(const Model& model, Workspace& ws, DerivativeWorkspace& d,
                              const MatX& K, MatX& Y);

}  // namespace femdyn
