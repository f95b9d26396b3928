// What one step of each integrator does to a linear mode: its stability function, from which
// the largest stable step follows (sim/stability.hpp, largest_stable_step).
//
// Every integrator of kIntegrators gives its own StepStability<K>; the template has no general
// definition, so a new integrator without one does not compile (with_step_stability
// instantiates them all), and none borrows another's region in silence.
//
// A mode λ of A, mirrored into the left half-plane (λ̃ = −|Re λ| + i Im λ: a growing mode, such
// as a fall, sets the same step limit as its decaying mirror), is stable under a step h if
//   Runge–Kutta methods:  |R(h λ̃)| ≤ 1, R the method's stability polynomial;
//   semi-implicit Euler:  judged on the oscillators x″ = k x + d ẋ that pairs of modes make
//                         (its step is not a map of the first-order modes one by one):
//                         the spectral radius of [[1 + h²k, h(1 + hd)], [hk, 1 + hd]] ≤ 1;
//   BDF:                  no bound (implicit; its adaptive step follows its error control).
#pragma once
#include <Eigen/Eigenvalues>
#include <array>
#include <complex>
#include <cstddef>
#include <vector>

#include "sim/integrator.hpp"

namespace femdyn {

// An oscillator x″ = k x + d ẋ of the linearised motion (sim/stability.cpp, euler_oscillators).
struct Oscillator {
  double k = 0, d = 0;
};

// The modes a step is judged on: the eigenvalues of A, and (where a method asks for them,
// needs_oscillators) their pairs as oscillators.
struct ModeSet {
  const Eigen::VectorXcd& eigenvalues;
  const std::vector<Oscillator>& oscillators;
};

inline constexpr double kStabilitySlack = 1 + 1e-12;

// |R(z)| ≤ 1 on every mirrored mode, R(z) = Σ c_k z^k (Horner).
template <std::size_t N>
bool polynomial_stable(const std::array<double, N>& c, const ModeSet& modes, double h) {
  for (const std::complex<double>& lambda : modes.eigenvalues) {
    const std::complex<double> z =
        h * std::complex<double>(-std::abs(lambda.real()), lambda.imag());
    std::complex<double> r = c[N - 1];
    for (std::size_t k = N - 1; k-- > 0;) r = r * z + c[k];
    if (std::abs(r) > kStabilitySlack) return false;
  }
  return true;
}

template <IntegratorKind K>
struct StepStability;  // no general definition: each integrator gives its own

template <>
struct StepStability<IntegratorKind::Rk4> {
  static constexpr bool bounded = true, needs_oscillators = false;
  // R(z) = 1 + z + z²/2 + z³/6 + z⁴/24
  static constexpr std::array<double, 5> R = {1, 1, 1.0 / 2, 1.0 / 6, 1.0 / 24};
  static bool stable(const ModeSet& modes, double h) { return polynomial_stable(R, modes, h); }
};

template <>
struct StepStability<IntegratorKind::Dopri> {
  static constexpr bool bounded = true, needs_oscillators = false;
  // Dormand–Prince 5(4), the propagated fifth-order solution: the Taylor terms of e^z to z⁵
  // and z⁶/600 (Hairer, Nørsett & Wanner, Solving ODEs I, II.4).
  static constexpr std::array<double, 7> R = {1,        1,         1.0 / 2,  1.0 / 6,
                                              1.0 / 24, 1.0 / 120, 1.0 / 600};
  static bool stable(const ModeSet& modes, double h) { return polynomial_stable(R, modes, h); }
};

template <>
struct StepStability<IntegratorKind::Euler> {
  static constexpr bool bounded = true, needs_oscillators = true;
  static bool stable(const ModeSet& modes, double h) {
    for (const Oscillator& o : modes.oscillators) {
      Eigen::Matrix2d G;  // (x, ẋ) ↦ one step's (x, ẋ)
      G << 1 + h * h * o.k, h * (1 + h * o.d), h * o.k, 1 + h * o.d;
      if (Eigen::EigenSolver<Eigen::Matrix2d>(G, false).eigenvalues().cwiseAbs().maxCoeff() >
          kStabilitySlack)
        return false;
    }
    return true;
  }
};

template <>
struct StepStability<IntegratorKind::Bdf> {
  static constexpr bool bounded = false, needs_oscillators = false;
  static bool stable(const ModeSet&, double) { return true; }
};

// f(StepStability<kind>{}), the kind chosen at run time among kIntegrators.
template <std::size_t I = 0, class F>
decltype(auto) with_step_stability(IntegratorKind kind, F&& f) {
  constexpr IntegratorKind K = kIntegrators[I];
  if constexpr (I + 1 == std::size(kIntegrators)) {
    return f(StepStability<K>{});
  } else {
    if (kind == K) return f(StepStability<K>{});
    return with_step_stability<I + 1>(kind, std::forward<F>(f));
  }
}

}  // namespace femdyn
