// The twin's linear couplings (twin_impl.hpp): θ = C q + θ0 as coordinate couplers among the
// mobilities. The nonlinear laws and the rods are twin_loops.cpp's. Compiled like twin.cpp
// (C++17, without NDEBUG).
#include <Simbody.h>

#include <memory>
#include <vector>

#include "core/model/errors.hpp"
#include "validation/twin_impl.hpp"

namespace femdyn::validation {

std::vector<int> independent_thetas(const TwinModel& model) {
  // Row j of C is e_k: its only stored non-zero is a 1 in column k (explicit zeros ignored).
  const int nt = model.n_theta(), n = model.n();
  std::vector<int> nonzeros(nt, 0), column(nt, -1);
  std::vector<double> value(nt, 0);
  for (int k = 0; k < model.C.outerSize(); ++k)
    for (SpMatX::InnerIterator it(model.C, k); it; ++it) {
      if (it.value() == 0) continue;
      const auto j = static_cast<std::size_t>(it.row());
      ++nonzeros[j], column[j] = k, value[j] = it.value();
    }
  std::vector<int> out(n, -1);
  for (int j = 0; j < nt; ++j)  // the first such θ_j, as the scan by rows found it
    if (model.theta0[j] == 0 && nonzeros[j] == 1 && value[j] == 1.0 && out[column[j]] < 0)
      out[column[j]] = j;
  return out;
}

int coordinates_of(TwinBody::Joint type) {
  switch (type) {
    case TwinBody::Joint::Fixed:
      return 0;
    case TwinBody::Joint::Spherical:
      return 4;
    case TwinBody::Joint::Free:
      return 7;
    case TwinBody::Joint::Universal:
      return 2;
    case TwinBody::Joint::Planar:
      return 3;
    default:
      return 1;
  }
}

int TwinModel::theta_of_rate(int j) const {
  const TwinBody& tb = bodies[theta_body[j]];
  return tb.theta + (j - (tb.rate >= 0 ? tb.rate : tb.theta));
}

std::vector<int> TwinModel::configuration_layout(const std::vector<int>& own_rate, int& n_q) const {
  std::vector<int> first(bodies.size(), -1);
  n_q = 0;
  for (const int j : own_rate) {
    if (j < 0) throw femdyn::Error("a coordinate drives no joint directly");
    const TwinBody& tb = bodies[theta_body[j]];
    if (j == (tb.rate >= 0 ? tb.rate : tb.theta))
      first[theta_body[j]] = n_q, n_q += coordinates_of(tb.joint);
  }
  return first;
}

int independent_theta(const TwinModel& model, int k) { return independent_thetas(model).at(k); }

void SimbodyTwin::Impl::add_linear_couplers() {
  using namespace SimTK;
  const TwinModel& m = model;
  independent = independent_thetas(m);
  std::vector<bool> is_independent(m.n_theta(), false);
  for (int k = 0; k < m.n(); ++k) {
    if (independent[k] < 0)
      couplers = false;
    else
      is_independent[independent[k]] = true;
  }
  if (couplers) {
    for (int j = 0; j < m.n_theta(); ++j) {
      if (is_independent[j]) continue;
      // f(θ_j, θ_ind(k)...) = θ_j − Σ_k C_jk θ_ind(k) − θ0_j = 0
      std::vector<MobilizedBodyIndex> bodies{mobod[m.theta_body[j]].getMobilizedBodyIndex()};
      std::vector<MobilizerQIndex> which{MobilizerQIndex(0)};
      std::vector<double> coeff{1.0};
      for (decltype(C_rows)::InnerIterator it(C_rows, j); it; ++it) {
        if (it.value() == 0) continue;
        bodies.push_back(mobod[m.theta_body[independent[it.col()]]].getMobilizedBodyIndex());
        which.push_back(MobilizerQIndex(0));
        coeff.push_back(-it.value());
      }
      coeff.push_back(-m.theta0[j]);
      Vector a(static_cast<int>(coeff.size()));
      for (int i = 0; i < a.size(); ++i) a[i] = coeff[i];
      auto f = std::make_unique<Function::Linear>(a);
      Constraint::CoordinateCoupler(matter, f.release(), bodies, which);  // Simbody owns f
    }
  }
}

}  // namespace femdyn::validation
