#include "core/derivatives/coupling.hpp"

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"

namespace femdyn {

LawDerivatives::LawDerivatives(const Model& m)
    : tree(std::make_unique<DerivativeWorkspace>(*m.tree)) {
  const CouplingLevel& L = *m.coupling_level;
  const int n = L.n, nt = L.n_theta;
  for (MatX* X : {&G, &Theta, &A_bar, &Gamma, &inner, &MX}) X->setZero(nt, n);
  W.setZero(n, n);
  theta = VecX::Zero(L.n_theta_q);
  for (VecX* v : {&theta_dot, &Gqdd, &gamma, &theta_ddot, &weight}) v->setZero(nt);
  int df_size = 0, d2f_size = 0;
  for (const CoupledJoint& j : L.coupled) {
    const int k = static_cast<int>(j.sources.size());
    df_at.push_back(df_size);
    d2f_at.push_back(d2f_size);
    df_size += k;
    d2f_size += k * k;
  }
  df.assign(df_size, 0.0);
  d2f.assign(d2f_size, 0.0);
  const int k = L.largest_arity;
  x.assign(k, 0.0);
  d3f.assign(k * k * k, 0.0);
}

LawDerivatives::~LawDerivatives() = default;

std::string law_derivatives_unsupported(const Model& m) {
  const std::string why = derivatives_unsupported(*m.tree);
  return why.empty() ? "" : why + " (in the tree under the coupling laws)";
}

namespace {

// A coordinate's rows: G_t = e_a, θ̇_t = q̇_a, (G q̈)_t = q̈_a, γ_t = 0, Θ_t = Ā_t = Γ_t = 0.
void coordinate_rows(const CouplingLevel& L, const VecX& q, const VecX& qd, const VecX& qdd,
                     LawDerivatives& c) {
  for (std::size_t i = 0; i < L.configuration_theta.size(); ++i)
    c.theta[L.configuration_theta[i]] = q[i];
  for (int a = 0; a < L.n; ++a) {
    const int t = L.coordinate_theta[a];
    c.G.row(t).setZero();
    c.G(t, a) = 1;
    c.theta_dot[t] = qd[a];
    c.Gqdd[t] = qdd[a];
    c.gamma[t] = 0;
    c.Theta.row(t).setZero();
    c.A_bar.row(t).setZero();
    c.Gamma.row(t).setZero();
  }
}

// The rows of joint t following s_1 … s_k by f (its f_k, f_kl, f_klp at df, d2f, d3f), from
// those of its sources (header comment).
void coupled_rows(const CoupledJoint& j, const double* df, const double* d2f, const double* d3f,
                  LawDerivatives& c) {
  const int t = j.theta, k = static_cast<int>(j.sources.size());
  c.G.row(t).setZero();
  c.Theta.row(t).setZero();
  c.A_bar.row(t).setZero();
  c.Gamma.row(t).setZero();
  c.theta_dot[t] = c.Gqdd[t] = c.gamma[t] = 0;
  for (int i = 0; i < k; ++i) {
    const int si = j.sources[i];
    const double fi = df[i];
    c.G.row(t) += fi * c.G.row(si);
    c.theta_dot[t] += fi * c.theta_dot[si];
    c.Gqdd[t] += fi * c.Gqdd[si];
    c.gamma[t] += fi * c.gamma[si];
    c.Theta.row(t) += fi * c.Theta.row(si);
    c.A_bar.row(t) += fi * c.A_bar.row(si);
    c.Gamma.row(t) += fi * c.Gamma.row(si);
    for (int l = 0; l < k; ++l) {
      const int sl = j.sources[l];
      const double fil = d2f[i * k + l];
      c.gamma[t] += fil * c.theta_dot[si] * c.theta_dot[sl];
      c.Theta.row(t) += fil * c.theta_dot[si] * c.G.row(sl);
      c.A_bar.row(t) += fil * c.Gqdd[si] * c.G.row(sl);
      c.Gamma.row(t) += fil * (c.gamma[si] * c.G.row(sl) + c.theta_dot[sl] * c.Theta.row(si) +
                               c.theta_dot[si] * c.Theta.row(sl));
      for (int p = 0; p < k; ++p)
        c.Gamma.row(t) +=
            d3f[(i * k + l) * k + p] * c.theta_dot[si] * c.theta_dot[sl] * c.G.row(j.sources[p]);
    }
  }
}

// θ, G, θ̇, G q̈, γ and the rows Θ, Ā, Γ at (q, q̇, q̈), the laws' f_k and f_kl kept; false where
// a law is not defined.
bool chain_rows(const CouplingLevel& L, const VecX& q, const VecX& qd, const VecX& qdd,
                LawDerivatives& c) {
  coordinate_rows(L, q, qd, qdd, c);
  for (std::size_t cj = 0; cj < L.coupled.size(); ++cj) {
    const CoupledJoint& j = L.coupled[cj];
    const auto k = j.sources.size();
    for (std::size_t i = 0; i < k; ++i) c.x[i] = c.theta[L.theta_q[j.sources[i]]];
    double* df = c.df.data() + c.df_at[cj];
    double* d2f = c.d2f.data() + c.d2f_at[cj];
    const std::span<const double> x(c.x.data(), k);
    double f = 0;
    if (!j.law->evaluate(x, f, {df, k}, {d2f, k * k})) return false;
    j.law->third_derivatives(x, {c.d3f.data(), k * k * k});
    c.theta[L.theta_q[j.theta]] = f;
    coupled_rows(j, df, d2f, c.d3f.data(), c);
  }
  return true;
}

// W = Σ_t τ_θ,t H_t by reverse accumulation through the laws (header comment).
void weighted_hessian(const CouplingLevel& L, const VecX& tau_theta, LawDerivatives& c) {
  c.weight = tau_theta;
  c.W.setZero();
  for (std::size_t cj = L.coupled.size(); cj-- > 0;) {
    const CoupledJoint& j = L.coupled[cj];
    const int k = static_cast<int>(j.sources.size());
    const double w = c.weight[j.theta];
    if (w == 0) continue;
    const double* df = c.df.data() + c.df_at[cj];
    const double* d2f = c.d2f.data() + c.d2f_at[cj];
    for (int i = 0; i < k; ++i) {
      for (int l = 0; l < k; ++l)
        if (d2f[i * k + l] != 0)
          c.W.noalias() +=
              (w * d2f[i * k + l]) * c.G.row(j.sources[i]).transpose() * c.G.row(j.sources[l]);
      c.weight[j.sources[i]] += df[i] * w;
    }
  }
}

}  // namespace

void law_inverse_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                             const VecX& qd, const VecX& qdd) {
  LawDerivatives& c = *d.law;
  const CouplingLevel& L = *m.coupling_level;
  if (!chain_rows(L, q, qd, qdd, c)) joint_state(m, ws, q, qd);  // throws, naming the law
  c.theta_ddot = c.Gqdd + c.gamma;                               // θ̈ = G q̈ + γ
  const Model& tree = *m.tree;
  Workspace& wt = *ws.tree;
  inverse_dynamics_derivatives(tree, wt, *c.tree, c.theta, c.theta_dot, c.theta_ddot);
  inverse_dynamics(tree, wt, c.theta, c.theta_dot, c.theta_ddot);  // τ_θ
  mass_matrix(tree, wt, c.theta);                                  // M_θ
  weighted_hessian(L, wt.tau, c);
  const MatX &Kq = c.tree->dtau_dq, &Kv = c.tree->dtau_dv, &M = wt.Ms;
  // ∂τ_q/∂q = W + Gᵀ (K_q G + K_v Θ + M_θ (Ā + Γ))
  c.MX = c.A_bar + c.Gamma;
  c.inner.noalias() = Kq * c.G;
  c.inner.noalias() += Kv * c.Theta;
  c.inner.noalias() += M * c.MX;
  d.dtau_dq = c.W;
  d.dtau_dq.noalias() += c.G.transpose() * c.inner;
  // ∂τ_q/∂v = Gᵀ (K_v G + 2 M_θ Θ)
  c.inner.noalias() = Kv * c.G;
  c.inner.noalias() += 2.0 * (M * c.Theta);
  d.dtau_dv.noalias() = c.G.transpose() * c.inner;
}

Status law_forward_derivatives(const Model& m, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                               const VecX& qd, const VecX& tau) {
  const Status st = forward_dynamics(m, ws, q, qd, tau);
  if (!st.ok) return st;
  d.qdd = ws.qdd;
  law_inverse_derivatives(m, ws, d, q, qd, d.qdd);
  d.Minv.setIdentity();  // (M^s)⁻¹ by the factor of Gᵀ M_θ G the forward dynamics left
  ws.reduced.solveInPlace(d.Minv);
  d.dqdd_dq.noalias() = -d.Minv * d.dtau_dq;
  d.dqdd_dv.noalias() = -d.Minv * d.dtau_dv;
  return st;
}

}  // namespace femdyn
