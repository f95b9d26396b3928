#include "core/derivatives/inverse_mass.hpp"

#include <algorithm>
#include <utility>

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/articulated.hpp"
#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"

namespace femdyn {
namespace {

// Up to this n, ∂q̈/∂· = −(M^s)⁻¹ ∂τ/∂· as products with (M^s)⁻¹; above, by the factorisation eight
// columns at a time. Measured crossover (products by subtract_block_times): chain64 72 µs by
// products against 112 µs, chain128 422 µs against 423 µs, chain256 2.98 ms against 1.70 ms.
constexpr int kDenseProductSize = 96;

// x ← (M^s)⁻¹ x by the factorisation forward_dynamics left.
void solve_column(const Model& m, Workspace& ws, VecX& x) {
  if (m.dynamics_route == DynamicsRoute::Articulated)
    articulated_solve(m, ws, x);
  else
    ws.solver.solve_in_place(x);
}

// Y ← −(M^s)⁻¹ Y column by column (sign −1), or (M^s)⁻¹ Y.
void solve_columns(const Model& m, Workspace& ws, DerivativeWorkspace& d, MatX& Y, double sign) {
  for (Eigen::Index k = 0; k < Y.cols(); ++k) {
    d.column = sign * Y.col(k);
    solve_column(m, ws, d.column);
    Y.col(k) = d.column;
  }
}

// The sweep's steps for a joint of one rate r (its column S and U, d of the factorisation), on
// each column j in one pass. Leaves to root, over the subtree's columns:
//   u_j = e_r(j) − S · P_j,   and below a parent P_j += (U/d) u_j.
void one_rate_forces(const ArticulatedBody& A, bool parent, int r, int count,
                     Eigen::Matrix<double, 6, Eigen::Dynamic>& P, Eigen::Ref<VecX> u) {
  const Vec6 S = A.S, K = A.U / A.d;
  for (int j = r; j < r + count; ++j) u[j] = -S.dot(P.col(j));
  u[r] += 1.0;
  if (parent)
    for (int j = r; j < r + count; ++j) P.col(j) += K * u[j];
}

// Root to leaves, over the block's columns from r on, the parent's accelerations a_j at columns
// from + j and the body's at to + j (the same: in place; −1: none, a_j = 0 or not kept):
//   x_j = u_j / d − (U/d) · a_j,   a_j of the body = a_j + S x_j.
void one_rate_accelerations(const ArticulatedBody& A, Eigen::Index from, Eigen::Index to, int r,
                            int count, Eigen::Matrix<double, 6, Eigen::Dynamic>& acc,
                            Eigen::Ref<VecX> x) {
  const Vec6 S = A.S, K = A.U / A.d;
  const double inv_d = 1 / A.d;
  if (from < 0) {
    for (int j = r; j < r + count; ++j) x[j] *= inv_d;
    if (to >= 0)
      for (int j = r; j < r + count; ++j) acc.col(to + j) = S * x[j];
    return;
  }
  if (to < 0) {
    for (int j = r; j < r + count; ++j) x[j] = x[j] * inv_d - K.dot(acc.col(from + j));
    return;
  }
  for (int j = r; j < r + count; ++j) {
    const Vec6 a = acc.col(from + j);
    x[j] = x[j] * inv_d - K.dot(a);
    acc.col(to + j) = a + S * x[j];
  }
}

// (M^s)⁻¹ into d.Minv in O(n · bodies) from the articulated factorisation forward_dynamics left
// in ws: articulated_solve applied to all n unit vectors at once. Leaves to root, the unit
// vectors of a subtree's rates are the only ones with articulated forces below it, so one 6 × n
// matrix P holds every body's (its subtree's columns): u = e − Sᵀ P, P += U D⁻¹ u on them. Root
// to leaves, rows r of the joint: x = D⁻¹ u − D⁻¹ Uᵀ a_parent, a = a_parent + S x, on the
// columns from the joint's first rate on (the upper triangle; the rest by symmetry). Row r of
// (M^s)⁻¹ is formed as column r (M^s is symmetric), so that every access is contiguous. Only the
// rates of the body's block of (M^s)⁻¹ (block_first, block_end) are formed: the rest is zero.
void inverse_mass_sweep(const Model& m, const Workspace& ws, DerivativeWorkspace& d) {
  InverseMassSweep& sweep = d.sweep;
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  MatX& X = d.Minv;
  sweep.P.setZero();
  for (int b = nb - 1; b >= 0; --b) {
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    const int r0 = J.idx_v, cnt = sweep.sub_count[b], after = sweep.block_end[b] - r0 - cnt;
    if (J.nv == 1) {
      one_rate_forces(ws.articulated[b], m.bodies[b].parent >= 0, r0, cnt, sweep.P, X.col(r0));
      X.col(r0).segment(r0 + cnt, after).setZero();
      continue;
    }
    auto Pb = sweep.P.middleCols(r0, cnt);
    for (int k = 0; k < J.nv; ++k) {
      const Vec6 minus_S = -ws.subspace[r0 + k];
      auto u = X.col(r0 + k);
      u.segment(r0, cnt).noalias() = Pb.transpose() * minus_S;
      u[r0 + k] += 1.0;
      u.segment(r0 + cnt, after).setZero();
    }
    if (m.bodies[b].parent < 0) continue;
    for (int k = 0; k < J.nv; ++k)
      Pb.noalias() += ws.articulated_rate[r0 + k].K * X.col(r0 + k).segment(r0, cnt).transpose();
  }
  for (int b = 0; b < nb; ++b) {
    const Body& body = m.bodies[b];
    const Joint& J = body.joint;
    const int p = body.parent, ps = p >= 0 ? sweep.slot[p] : -1, s = sweep.slot[b];
    if (!moves(J)) {  // a fixed joint passes its parent's accelerations on
      if (s < 0 || s == ps) continue;
      const int c0 = sweep.sub_first[b], L = sweep.block_end[b] - c0;
      if (ps >= 0)
        sweep.A.middleCols(s * n + c0, L) = sweep.A.middleCols(ps * n + c0, L);
      else
        sweep.A.middleCols(s * n + c0, L).setZero();
      continue;
    }
    const int r0 = J.idx_v, L = sweep.block_end[b] - r0;
    if (J.nv == 1) {
      one_rate_accelerations(ws.articulated[b], ps >= 0 ? ps * n : -1, s >= 0 ? s * n : -1, r0, L,
                             sweep.A, X.col(r0));
      continue;
    }
    auto u = sweep.rows.topLeftCorner(L, J.nv);
    u = X.block(r0, r0, L, J.nv);
    for (int k = 0; k < J.nv; ++k) {
      const ArticulatedRate& R = ws.articulated_rate[r0 + k];
      auto x = X.col(r0 + k).segment(r0, L);
      x.noalias() = u * R.Dinv.head(J.nv);
      if (ps >= 0) x.noalias() -= sweep.A.middleCols(ps * n + r0, L).transpose() * R.K;
    }
    if (s < 0) continue;
    auto As = sweep.A.middleCols(s * n + r0, L);
    if (ps >= 0) {
      if (s != ps) As = sweep.A.middleCols(ps * n + r0, L);
    } else {
      As.setZero();
    }
    for (int k = 0; k < J.nv; ++k)
      As.noalias() += ws.subspace[r0 + k] * X.col(r0 + k).segment(r0, L).transpose();
  }
  for (int b = 0; b < nb; ++b) {  // the upper triangle from the lower; outside the blocks 0
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    const int first = sweep.block_first[b], end = sweep.block_end[b];
    for (int c = J.idx_v; c < J.idx_v + J.nv; ++c) {
      X.col(c).head(first).setZero();
      X.col(c).tail(n - end).setZero();
      for (int r = first; r < c; ++r) X(r, c) = X(c, r);
    }
  }
}

// Y ← sign (M^s)⁻¹ Y by the articulated factorisation (articulated_solve's steps) on eight
// columns at a time: O(bodies) per column, as the column solves, with the per-body work shared.
void solve_chunks(const Model& m, const Workspace& ws, DerivativeWorkspace& d, MatX& Y,
                  double sign) {
  InverseMassSweep& sweep = d.sweep;
  using Row8 = Eigen::Matrix<double, 1, 8>;
  const int nb = static_cast<int>(m.bodies.size());
  for (Eigen::Index c0 = 0; c0 < Y.cols(); c0 += 8) {
    const Eigen::Index w = std::min<Eigen::Index>(8, Y.cols() - c0);
    if (w < 8) sweep.chunk.setZero();
    sweep.chunk.leftCols(w) = sign * Y.middleCols(c0, w);
    for (int b = nb - 1; b >= 0; --b) {  // leaves to root: u = f − Sᵀ p, p += U D⁻¹ u
      const Body& body = m.bodies[b];
      const Joint& J = body.joint;
      auto& p = sweep.chunk_force[b];
      if (J.nv == 1) {
        const ArticulatedBody& A = ws.articulated[b];
        auto x = sweep.chunk.row(J.idx_v);
        x.noalias() -= A.S.transpose() * p;
        p.noalias() += (A.U / A.d) * x;
      } else if (J.nv > 1) {
        for (int k = 0; k < J.nv; ++k)
          sweep.chunk.row(J.idx_v + k).noalias() -= ws.subspace[J.idx_v + k].transpose() * p;
        for (int k = 0; k < J.nv; ++k)
          p.noalias() += ws.articulated_rate[J.idx_v + k].K * sweep.chunk.row(J.idx_v + k);
      }
      if (body.parent >= 0) sweep.chunk_force[body.parent] += p;
      p.setZero();  // ready for the next chunk
    }
    for (int b = 0; b < nb; ++b) {  // root to leaves: x = D⁻¹ u − D⁻¹ Uᵀ a, a += S x
      const Body& body = m.bodies[b];
      const Joint& J = body.joint;
      auto& a = sweep.chunk_acceleration[b];
      if (body.parent >= 0)
        a = sweep.chunk_acceleration[body.parent];
      else
        a.setZero();
      if (J.nv == 1) {
        const ArticulatedBody& A = ws.articulated[b];
        auto x = sweep.chunk.row(J.idx_v);
        x = (x - A.U.transpose() * a) / A.d;
        a.noalias() += A.S * x;
      } else if (J.nv > 1) {
        Eigen::Matrix<double, 6, 8> u;
        u.topRows(J.nv) = sweep.chunk.middleRows(J.idx_v, J.nv);
        for (int k = 0; k < J.nv; ++k) {
          const ArticulatedRate& R = ws.articulated_rate[J.idx_v + k];
          Row8 x = R.Dinv.head(J.nv).transpose() * u.topRows(J.nv);
          x.noalias() -= R.K.transpose() * a;
          sweep.chunk.row(J.idx_v + k) = x;
        }
        for (int k = 0; k < J.nv; ++k)
          a.noalias() += ws.subspace[J.idx_v + k] * sweep.chunk.row(J.idx_v + k);
      }
    }
    Y.middleCols(c0, w) = sweep.chunk.leftCols(w);
  }
}

// Y = −(M^s)⁻¹ K by the factorisation forward_dynamics left: the articulated one eight columns at
// a time (the sweep's route), else column by column.
void minus_minv_solve(const Model& m, Workspace& ws, DerivativeWorkspace& d, const MatX& K,
                      MatX& Y) {
  Y = K;
  if (d.sweep.applies)
    solve_chunks(m, ws, d, Y, -1.0);
  else
    solve_columns(m, ws, d, Y, -1.0);
}

// The rows where a column of ∂τ/∂q or ∂τ/∂v of body b's rates can be non-zero: the rates of b's
// ancestors and of b's subtree (a pair (c, m) couples only along one path to the root), as runs
// of consecutive rates, merged. Needs the sweep's depth-first numbering (sub_first, sub_count).
// A two-point spring couples the rates of its two bodies' paths across branches: with springs
// every column is taken whole. Consecutive bodies with the same rows (the bodies of a chain
// segment below its last branching: each one's ancestors and subtree are the segment's whole
// path) form one group of columns. A run is cut where a block of (M^s)⁻¹ ends (with springs).
void plan_row_runs(const Model& m, InverseMassSweep& s) {
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  s.groups.clear();
  s.runs.clear();
  std::vector<int> rate_block(n);  // per rate, the body whose block it is in
  for (int b = 0; b < nb; ++b) {
    const Joint& J = m.bodies[b].joint;
    if (moves(J)) std::fill_n(rate_block.begin() + J.idx_v, J.nv, b);
  }
  std::vector<std::pair<int, int>> rows, merged;  // (first, count), root first
  std::vector<RowRun> cut;
  for (int b = 0; b < nb; ++b) {
    const Joint& J = m.bodies[b].joint;
    if (!moves(J)) continue;
    merged.clear();
    if (!m.springs.empty()) {
      merged.emplace_back(0, m.n());
    } else {
      rows.clear();
      rows.emplace_back(s.sub_first[b], s.sub_count[b]);
      for (int a = m.bodies[b].parent; a >= 0; a = m.bodies[a].parent)
        if (moves(m.bodies[a].joint))
          rows.emplace_back(m.bodies[a].joint.idx_v, m.bodies[a].joint.nv);
      std::sort(rows.begin(), rows.end());
      for (const auto& [first, count] : rows)
        if (!merged.empty() && merged.back().first + merged.back().second == first)
          merged.back().second += count;
        else
          merged.emplace_back(first, count);
    }
    cut.clear();
    for (const auto& [first, count] : merged)
      for (int r = first; r < first + count;) {
        const int blk = rate_block[r];
        const int end = std::min(first + count, s.block_end[blk]);
        cut.push_back({r, end - r, s.block_first[blk], s.block_end[blk]});
        r = end;
      }
    const auto same = [](const RowRun& x, const RowRun& y) {
      return x.first == y.first && x.count == y.count;  // (the same rates: the same blocks)
    };
    if (!s.groups.empty()) {
      ColumnGroup& g = s.groups.back();
      if (g.first + g.count == J.idx_v &&
          std::equal(s.runs.begin() + g.run_begin, s.runs.end(), cut.begin(), cut.end(), same)) {
        g.count += J.nv;
        continue;
      }
    }
    const int begin = static_cast<int>(s.runs.size());
    s.runs.insert(s.runs.end(), cut.begin(), cut.end());
    s.groups.push_back({J.idx_v, J.nv, begin, static_cast<int>(s.runs.size())});
  }
}

// y −= X k for a column-major block X (rows × count, column stride ld), four columns at a time
// so that y is read and written once per four. The only kernel compiled twice, for x86-64-v3
// (AVX2 and FMA: 4-wide) and for the baseline the library is built for, the processor choosing
// once when the program loads (target_clones, GCC and Clang): on floating Atlas, whose block is
// all 36 rates, the products take about 2 µs less.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
[[gnu::target_clones("arch=x86-64-v3", "default")]]
#endif
void subtract_block_times(double* __restrict y, const double* X, Eigen::Index ld, int rows,
                          int count, const double* k) {
  int j = 0;
  for (; j + 4 <= count; j += 4) {
    const double* __restrict x0 = X + j * ld;
    const double* __restrict x1 = x0 + ld;
    const double* __restrict x2 = x1 + ld;
    const double* __restrict x3 = x2 + ld;
    const double k0 = k[j], k1 = k[j + 1], k2 = k[j + 2], k3 = k[j + 3];
    for (int i = 0; i < rows; ++i) y[i] -= (x0[i] * k0 + x1[i] * k1) + (x2[i] * k2 + x3[i] * k3);
  }
  for (; j < count; ++j) {
    const double* __restrict x0 = X + j * ld;
    const double kj = k[j];
    for (int i = 0; i < rows; ++i) y[i] -= x0[i] * kj;
  }
}

// Y = −(M^s)⁻¹ K over K's non-zero rows only (plan_row_runs), each run times its block of
// (M^s)⁻¹: per column a few small products.
void minus_minv_times(const DerivativeWorkspace& d, const MatX& K, MatX& Y) {
  const InverseMassSweep& sweep = d.sweep;
  for (const ColumnGroup& g : sweep.groups)
    for (int c = g.first; c < g.first + g.count; ++c) {
      auto y = Y.col(c);
      y.setZero();
      for (int r = g.run_begin; r < g.run_end; ++r) {
        const RowRun& run = sweep.runs[r];
        const int rows = run.block_end - run.block_first;
        subtract_block_times(y.data() + run.block_first, &d.Minv(run.block_first, run.first),
                             d.Minv.outerStride(), rows, run.count, K.col(c).data() + run.first);
      }
    }
}

// Whether the sweep applies (articulated route, every subtree's rates contiguous with the
// joint's own first), and its per-body layout.
void plan_inverse_sweep(const Model& m, InverseMassSweep& s) {
  const int n = m.n(), nb = static_cast<int>(m.bodies.size());
  if (m.dynamics_route != DynamicsRoute::Articulated || !m.identity_coupling) return;
  std::vector<int> lo(nb, n), hi(nb, -1);
  s.sub_count.assign(nb, 0);
  for (int b = nb - 1; b >= 0; --b) {
    const Joint& J = m.bodies[b].joint;
    if (moves(J)) {
      s.sub_count[b] += J.nv;
      lo[b] = std::min(lo[b], J.idx_v);
      hi[b] = std::max(hi[b], J.idx_v + J.nv - 1);
      if (lo[b] != J.idx_v) return;  // a descendant's rate before the joint's own
    }
    if (s.sub_count[b] > 0 && hi[b] - lo[b] + 1 != s.sub_count[b]) return;
    if (const int p = m.bodies[b].parent; p >= 0) {
      if (p >= b) return;
      s.sub_count[p] += s.sub_count[b];
      lo[p] = std::min(lo[p], lo[b]);
      hi[p] = std::max(hi[p], hi[b]);
    }
  }
  s.sub_first = lo;
  // Each body's block of (M^s)⁻¹: the subtree of its topmost moving ancestor-or-self, or its
  // own subtree if none moves (parents come before children here).
  std::vector<int> top(nb);
  s.block_first.assign(nb, 0);
  s.block_end.assign(nb, 0);
  for (int b = 0; b < nb; ++b) {
    const int p = m.bodies[b].parent;
    top[b] = p >= 0 && moves(m.bodies[top[p]].joint) ? top[p] : b;
    s.block_first[b] = s.sub_first[top[b]];
    s.block_end[b] = s.sub_first[top[b]] + s.sub_count[top[b]];
  }
  // The last child of each body with rates below it: it may reuse its parent's slot.
  std::vector<int> last(nb, -1);
  for (int b = 0; b < nb; ++b)
    if (const int p = m.bodies[b].parent; p >= 0 && s.sub_count[b] > 0) last[p] = b;
  s.slot.assign(nb, -1);
  int slots = 0;
  for (int b = 0; b < nb; ++b) {
    const int own = moves(m.bodies[b].joint) ? m.bodies[b].joint.nv : 0;
    if (s.sub_count[b] - own <= 0) continue;  // no rates below: its accelerations are not read
    const int p = m.bodies[b].parent;
    s.slot[b] = p >= 0 && s.slot[p] >= 0 && last[p] == b ? s.slot[p] : slots++;
  }
  plan_row_runs(m, s);
  s.P.setZero(6, n);
  s.A.setZero(6, static_cast<Eigen::Index>(slots) * n);
  s.rows.setZero(n, 6);
  s.chunk_force.assign(nb, Eigen::Matrix<double, 6, 8>::Zero());
  s.chunk_acceleration.assign(nb, Eigen::Matrix<double, 6, 8>::Zero());
  s.chunk.setZero(n, 8);
  s.applies = true;
}

}  // namespace

void InverseMassSweep::plan(const Model& m) { plan_inverse_sweep(m, *this); }

void inverse_mass_matrix(const Model& m, Workspace& ws, DerivativeWorkspace& d) {
  if (d.sweep.applies) return inverse_mass_sweep(m, ws, d);
  d.Minv.setIdentity();
  solve_columns(m, ws, d, d.Minv, 1.0);
}

void minus_inverse_mass_times(const Model& m, Workspace& ws, DerivativeWorkspace& d, const MatX& K,
                              MatX& Y) {
  if (m.n() > kDenseProductSize)
    minus_minv_solve(m, ws, d, K, Y);
  else if (d.sweep.applies)
    minus_minv_times(d, K, Y);
  else
    Y.noalias() = -d.Minv * K;
}

}  // namespace femdyn
