// Two-point springs (Model::springs): a linear spring-damper between two places A and B
// (core/model/attachment.hpp), Simbody's TwoPointLinearSpring with a damper along the line. With
// d = p_A − p_B, l = |d|, ê = d / l, the force on A is
//   f_A = −(k (l − l₀) + c l̇) ê,   l̇ = êᵀ (v_A − v_B),
// and −f_A on B, so that on the rates Q_s = (Jv_A − Jv_B)ᵀ f_A. Its potential ½ k (l − l₀)² is
// in the energy, and c l̇² is dissipated.
#pragma once
#include <string>

#include "core/model/attachment.hpp"

namespace femdyn {

// One spring of Model::springs; its forces are core/dynamics/springs.hpp's.
struct TwoPointSpring {
  std::string name;
  Attachment a, b;
  double stiffness = 0, rest_length = 0, damping = 0;
  std::string where;
};

}  // namespace femdyn
