// The coupling level θ = C q + θ0 (θ̇ = C v) applied in the hot path: through the sparse copy of C
// (Model::C_sparse, O(non-zeros)), or, for the identity (no couplings), as nothing at all.
// Model::C (column-major, for M^s = Cᵀ M_θ C and reports) and C_sparse (row-major) hold
// the same entries.
#pragma once
#include "core/model/model.hpp"

namespace femdyn {

// The joints' coordinates θ = C_q q + θ0_q of the configuration q (n_q entries).
inline void coupling_configuration(const Model& m, const VecX& q, VecX& theta) {
  if (m.identity_coupling) {
    theta = q;
    return;
  }
  theta.noalias() = m.C_configuration * q;
  theta += m.theta0_configuration;
}

// The joints' rates θ̇ = C x of the generalized rates x (n entries).
inline void coupling_apply(const Model& m, const VecX& x, VecX& theta_dot) {
  if (m.identity_coupling) {
    theta_dot = x;
    return;
  }
  theta_dot.noalias() = m.C_sparse * x;
}

// y = Cᵀ f.
inline void coupling_apply_transpose(const Model& m, const VecX& f, VecX& y) {
  if (m.identity_coupling)
    y = f;
  else
    y.noalias() = m.C_sparse.transpose() * f;
}

// y += v · (row j of C)ᵀ for a vector y of n entries: a generalized force from joint j.
inline void coupling_add_row(const Model& m, int j, double v, VecX& y) {
  if (m.identity_coupling) {
    y[j] += v;
    return;
  }
  for (SpRowMat::InnerIterator it(m.C_sparse, j); it; ++it) y[it.col()] += it.value() * v;
}

// Y += v (row j of C) for a block Y of n columns (v a column): a Jacobian's joint-j term.
template <class Y, class V>
inline void coupling_add_row(const Model& m, int j, const V& v, Y&& y) {
  if (m.identity_coupling) {
    y.col(j) += v;
    return;
  }
  for (SpRowMat::InnerIterator it(m.C_sparse, j); it; ++it) y.col(it.col()) += it.value() * v;
}

}  // namespace femdyn
