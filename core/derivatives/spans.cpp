#include "core/derivatives/spans.hpp"

#include <algorithm>

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/span_inertia.hpp"

namespace femdyn {

std::string span_derivatives_unsupported(const Model& m) {
  const std::string why = span_inertia_unsupported(m);  // "<where>: an element spanning …"
  return why.empty() ? ""
                     : "derivatives need " + why.substr(0, why.find(": ")) +
                           " to use only its nodes' translations, with no velocity force";
}

void SpanDerivatives::size_for(const Model& m) {
  const int nt = m.n_theta();
  int most = 0;
  for (std::size_t i = 0; i < m.elements.size(); ++i)
    if (m.elements[i].spans) elements.push_back(static_cast<int>(i));
  for (SpanningMass& s : spanning_masses(m)) {  // in the same order
    most = std::max(most, static_cast<int>(s.body.size()));
    mass.push_back(std::move(s.mass));
  }
  node.assign(most, PointMotion{});
  path.assign(most, {});
  for (auto& p : path) p.reserve(nt);
  rates.reserve(nt);
  listed.assign(nt, 0);
  arm.assign(nt, Vec3::Zero());
  x_ddot.setZero(3 * most);
  force.setZero(3 * most);
  for (MatX* X : {&dxdd_dq, &dxdd_dv, &dF_dq, &dF_dv}) X->setZero(3 * most, nt);
}

namespace {

// The union of the k nodes' paths into buf.rates, their columns of ∂ẍ zeroed.
void gather_rates(int k, SpanDerivatives& buf) {
  buf.rates.clear();
  for (int l = 0; l < k; ++l)
    for (const int r : buf.path[l])
      if (!buf.listed[r]) buf.listed[r] = 1, buf.rates.push_back(r);
  for (const int r : buf.rates) {
    buf.listed[r] = 0;
    buf.dxdd_dq.col(r).setZero();
    buf.dxdd_dv.col(r).setZero();
  }
}

void add_element(const Model& m, const Workspace& ws, const DerivativeWorkspace& d,
                 const ElementEntry& e, const MatX& M, SpanDerivatives& buf, MatX& Kq, MatX& Kv) {
  const auto nodes = e.element->nodes();
  const int k = static_cast<int>(nodes.size());
  for (int l = 0; l < k; ++l) {
    const int b = e.node_body[l];
    const BodyState& B = ws.body[b];
    buf.node[l] = point_motion(d, b, B.p + B.R * nodes[l].position);
    buf.x_ddot.segment<3>(3 * l) = buf.node[l].x_ddot;
    rates_on_path(m, b, buf.path[l]);
  }
  auto F = buf.force.head(3 * k);
  F.noalias() = M * buf.x_ddot.head(3 * k);  // F_l = Σ_j M_lj (ẍ_j − g)
  gather_rates(k, buf);
  Vec3 dx_dot, dx_ddot;
  for (int l = 0; l < k; ++l)
    for (const int r : buf.path[l]) {
      point_position_derivative(m, d, buf.node[l], r, dx_dot, dx_ddot);
      buf.dxdd_dq.block<3, 1>(3 * l, r) = dx_ddot;
      buf.dxdd_dv.block<3, 1>(3 * l, r) = point_rate_derivative(m, d, buf.node[l], r);
    }
  for (const int r : buf.rates) {
    buf.dF_dq.col(r).head(3 * k).noalias() = M * buf.dxdd_dq.col(r).head(3 * k);
    buf.dF_dv.col(r).head(3 * k).noalias() = M * buf.dxdd_dv.col(r).head(3 * k);
  }
  for (int l = 0; l < k; ++l) {
    for (const int c : buf.path[l]) {
      const Vec3 J = point_velocity(d.S[c], buf.node[l].x);
      for (const int r : buf.rates) {
        Kq(c, r) += J.dot(buf.dF_dq.block<3, 1>(3 * l, r));
        Kv(c, r) += J.dot(buf.dF_dv.block<3, 1>(3 * l, r));
      }
    }
    add_point_turning(m, d, buf.node[l].x, F.segment<3>(3 * l), buf.path[l], buf.arm, Kq);
  }
}

}  // namespace

void add_span_derivatives(const Model& m, const Workspace& ws, DerivativeWorkspace& d, MatX& Kq,
                          MatX& Kv) {
  SpanDerivatives& buf = d.spans;
  for (std::size_t i = 0; i < buf.elements.size(); ++i)
    add_element(m, ws, d, m.elements[buf.elements[i]], buf.mass[i], buf, Kq, Kv);
}

}  // namespace femdyn
