// A coordinate whose motion is given as a function of time, q_p(t) (docs/model-format.md,
// joints: "prescribed"): a driven joint. The simulator holds it there by the joint torque that
// gives q̈_p = q̈_p(t) exactly (sim/motion.cpp), counted as work like any actuation; the
// equations at a state, which take τ as given, are unchanged.
#pragma once
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace femdyn {

struct PrescribedMotion {
  enum class Kind {
    // Simo & Vu-Quoc's smooth spin-up to rate ω_s in time T_s:
    //   q = (ω_s/T_s)(t²/2 + (T_s/2π)²(cos(2πt/T_s) − 1)) for t ≤ T_s, ω_s (t − T_s/2) after.
    SpinUp,
    Polynomial,  // q = Σ_k c_k t^k
  };
  Kind kind = Kind::Polynomial;
  double rate = 0, time = 1;         // SpinUp: ω_s, T_s
  std::vector<double> coefficients;  // Polynomial: c_0, c_1, …

  // (q, q̇, q̈) at t.
  std::array<double, 3> at(double t) const {
    if (kind == Kind::SpinUp) {
      if (t > time) return {rate * (t - time / 2), rate, 0.0};
      const double c = time / (2 * std::numbers::pi), k = rate / time;
      return {k * (t * t / 2 + c * c * (std::cos(t / c) - 1)), k * (t - c * std::sin(t / c)),
              k * (1 - std::cos(t / c))};
    }
    std::array<double, 3> out{0, 0, 0};
    for (std::size_t i = coefficients.size(); i-- > 0;) {  // Horner, with its derivatives
      out[2] = out[2] * t + 2 * out[1];
      out[1] = out[1] * t + out[0];
      out[0] = out[0] * t + coefficients[i];
    }
    return out;
  }
};

// A prescribed coordinate of the compiled model: q[coordinate] (a one-rate joint's) follows
// motion(t).
struct PrescribedCoordinate {
  int coordinate = -1;
  std::string joint;
  PrescribedMotion motion;
};

}  // namespace femdyn
