// femdyn's documented input limits (docs/robustness.md), enforced where the input is read or
// compiled, each with a one-line error naming the place and the limit.
#pragma once
#include <cmath>
#include <cstdio>
#include <string>

#include "core/model/errors.hpp"
#include "core/spatial/math.hpp"

namespace femdyn {

// Every physical input (lengths, masses, inertias, gravity, springs, loads, ratios, states) is a
// finite number of magnitude at most 1e100: the equations form products of a few of them
// (m g l, m l² θ̇², k θ), which then stay far from double precision's 1.8e308.
inline constexpr double kMaxMagnitude = 1e100;

// Sizes: enough for real robots and large generated trees, small enough that a model's memory
// (linear in the bodies) and its compile time stay within a few GB and seconds.
inline constexpr int kMaxBodies = 200'000;
inline constexpr int kMaxElements = 1'000'000;
inline constexpr long long kMaxFileBytes = 256LL << 20;  // a model file: 256 MiB
inline constexpr int kMaxNesting = 64;                   // JSON nesting depth
inline constexpr double kMaxTensorEntries = 2e7;         // D and T' (equations --tensor): 160 MB

// "1000000 bodies: more than femdyn's limit of 200000", wherever the bodies are counted (the
// JSON text before it is parsed, a URDF's links, compile()).
inline std::string too_many_bodies_text(std::size_t bodies) {
  return std::to_string(bodies) + " bodies: more than femdyn's limit of " +
         std::to_string(kMaxBodies);
}

inline std::string magnitude_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}

// How every refusal of a number past kMaxMagnitude ends, wherever the number was read (a model,
// the command line, a τ table, a Python argument): "1e+308 is out of range (|x| ≤ 1e100: …)".
inline constexpr const char* kOutOfRange =
    " is out of range (|x| ≤ 1e100: beyond it the equations' products overflow double precision)";
inline std::string out_of_range_text(double x) { return magnitude_text(x) + kOutOfRange; }

// "<what> is NaN or Inf", or "<what> 1e+308 is out of range (|x| ≤ 1e100: …)".
inline void check_magnitude(double x, const std::string& where, const std::string& what) {
  if (!std::isfinite(x)) throw ModelError(where, what + " is NaN or Inf");
  if (std::abs(x) > kMaxMagnitude) throw ModelError(where, what + " " + out_of_range_text(x));
}

inline void check_magnitude(const Vec3& v, const std::string& where, const std::string& what) {
  for (int k = 0; k < 3; ++k) check_magnitude(v[k], where, what);
}

}  // namespace femdyn
