// What a joint whose coordinates form a vector space (nq = nv, θ̇_J the derivative of θ_J) gives
// the kernel for its configuration: q ⊕ ξ = q + ξ, q₁ ⊖ q₀ = q₁ − q₀, ξ̇ = v in every chart,
// the neutral configuration 0, ∂ξ̇/∂ξ = 0. Every type but spherical and free inherits it.
#pragma once
#include <random>

namespace femdyn {

struct Joint;

template <int N>
struct FlatJoint {
  static constexpr bool flat = true;
  static void integrate(const Joint&, const double* q, const double* xi, double* out) {
    for (int k = 0; k < N; ++k) out[k] = q[k] + xi[k];
  }
  static void difference(const Joint&, const double* q0, const double* q1, double* xi) {
    for (int k = 0; k < N; ++k) xi[k] = q1[k] - q0[k];
  }
  static void chart_rate(const Joint&, const double*, const double*, const double* v,
                         double* xi_dot) {
    for (int k = 0; k < N; ++k) xi_dot[k] = v[k];
  }
  // ∂ξ̇/∂ξ at ξ = 0 (nv × nv, row-major into A, zero on entry): ξ̇ = v does not depend on ξ.
  static void chart_rate_jacobian(const Joint&, const double*, double*) {}
  // The suffix naming coordinate k (and rate k): "" for a joint of one coordinate.
  static const char* coordinate_name(int) { return ""; }
  static const char* rate_name(int k) { return coordinate_name(k); }
  static void neutral(double* q) {
    for (int k = 0; k < N; ++k) q[k] = 0;
  }
};

}  // namespace femdyn
