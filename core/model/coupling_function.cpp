#include "core/model/coupling_function.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/spatial/math.hpp"

namespace femdyn {

namespace {

// x^p for an integer p, 0 for p < 0 (the derivative of a constant factor), x^0 = 1.
double power(double x, int p) {
  if (p < 0) return 0;
  double r = 1;
  for (int k = 0; k < p; ++k) r *= x;
  return r;
}

// The angle in (−π, π].
double wrap(double a) { return std::remainder(a, 2 * std::numbers::pi); }

}  // namespace

bool LinearCoupling::evaluate(std::span<const double> x, double& f, std::span<double> df,
                              std::span<double> d2f) const {
  f = offset_;
  for (std::size_t k = 0; k < ratios_.size(); ++k) {
    f += ratios_[k] * x[k];
    df[k] = ratios_[k];
  }
  std::fill(d2f.begin(), d2f.end(), 0.0);
  return true;
}

void LinearCoupling::third_derivatives(std::span<const double>, std::span<double> d3f) const {
  std::fill(d3f.begin(), d3f.end(), 0.0);
}

namespace {

// c Π_k x_k^{p_k} with the factors of d1, d2, d3 differentiated once each (−1: none).
double term_derivative(const PolynomialCoupling::Term& t, std::span<const double> x, int d1,
                       int d2 = -1, int d3 = -1) {
  double r = t.coefficient;
  for (std::size_t k = 0; k < t.powers.size(); ++k) {
    int p = t.powers[k];
    double c = 1;
    for (const int d : {d1, d2, d3})
      if (static_cast<int>(k) == d) c *= p, --p;
    r *= c * power(x[k], p);
  }
  return r;
}

}  // namespace

bool PolynomialCoupling::evaluate(std::span<const double> x, double& f, std::span<double> df,
                                  std::span<double> d2f) const {
  const int n = arity_;
  f = 0;
  std::fill(df.begin(), df.end(), 0.0);
  std::fill(d2f.begin(), d2f.end(), 0.0);
  for (const Term& t : terms_) {
    f += term_derivative(t, x, -1);
    for (int k = 0; k < n; ++k) {
      if (t.powers[k] == 0) continue;
      df[k] += term_derivative(t, x, k);
      for (int l = 0; l < n; ++l) d2f[k * n + l] += term_derivative(t, x, k, l);
    }
  }
  return true;
}

void PolynomialCoupling::third_derivatives(std::span<const double> x, std::span<double> d3f) const {
  const int n = arity_;
  std::fill(d3f.begin(), d3f.end(), 0.0);
  for (const Term& t : terms_)
    for (int k = 0; k < n; ++k) {
      if (t.powers[k] == 0) continue;
      for (int l = 0; l < n; ++l)
        for (int p = 0; p < n; ++p) d3f[(k * n + l) * n + p] += term_derivative(t, x, k, l, p);
    }
}

SplineCoupling::SplineCoupling(std::vector<double> x, std::vector<double> y)
    : x_(std::move(x)), y_(std::move(y)), m_(x_.size(), 0.0) {
  // Natural spline: h_{i-1} m_{i-1} + 2(h_{i-1} + h_i) m_i + h_i m_{i+1}
  //   = 6((y_{i+1} − y_i)/h_i − (y_i − y_{i-1})/h_{i-1}),  m_0 = m_{N-1} = 0 (Thomas algorithm).
  const std::size_t N = x_.size();
  if (N < 3) return;
  std::vector<double> c(N, 0.0), d(N, 0.0);
  for (std::size_t i = 1; i + 1 < N; ++i) {
    const double h0 = x_[i] - x_[i - 1], h1 = x_[i + 1] - x_[i];
    const double diag = 2 * (h0 + h1) - h0 * c[i - 1];
    const double rhs = 6 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
    c[i] = h1 / diag;
    d[i] = (rhs - h0 * d[i - 1]) / diag;
  }
  for (std::size_t i = N - 2; i >= 1; --i) m_[i] = d[i] - c[i] * m_[i + 1];
}

bool SplineCoupling::evaluate(std::span<const double> xs, double& f, std::span<double> df,
                              std::span<double> d2f) const {
  const double x = xs[0];
  const std::size_t N = x_.size();
  // Beyond the ends: the straight line with the end slope (S'' = 0 there, so still C²).
  const auto slope = [&](std::size_t i, double t) {  // S' on [x_i, x_{i+1}] at x_i + t
    const double h = x_[i + 1] - x_[i];
    return (y_[i + 1] - y_[i]) / h - h * (2 * m_[i] + m_[i + 1]) / 6 + m_[i] * t +
           (m_[i + 1] - m_[i]) * t * t / (2 * h);
  };
  if (x <= x_.front() || x >= x_.back()) {
    const bool low = x <= x_.front();
    const std::size_t i = low ? 0 : N - 2;
    const double s = slope(i, low ? 0.0 : x_[N - 1] - x_[N - 2]);
    const double x0 = low ? x_.front() : x_.back(), y0 = low ? y_.front() : y_.back();
    f = y0 + s * (x - x0);
    df[0] = s;
    d2f[0] = 0;
    return true;
  }
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(x_.begin(), x_.end(), x) - x_.begin() - 1);
  const double h = x_[i + 1] - x_[i], a = (x_[i + 1] - x) / h, b = (x - x_[i]) / h;
  f = a * y_[i] + b * y_[i + 1] +
      ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * h * h / 6;
  df[0] = slope(i, x - x_[i]);
  d2f[0] = a * m_[i] + b * m_[i + 1];
  return true;
}

void SplineCoupling::third_derivatives(std::span<const double> xs, std::span<double> d3f) const {
  const double x = xs[0];
  d3f[0] = 0;  // the straight lines beyond the ends
  if (x <= x_.front() || x >= x_.back()) return;
  const std::size_t i =  // the interval evaluate takes: S''' = (m_{i+1} − m_i) / h on it
      static_cast<std::size_t>(std::upper_bound(x_.begin(), x_.end(), x) - x_.begin() - 1);
  d3f[0] = (m_[i + 1] - m_[i]) / (x_[i + 1] - x_[i]);
}

bool FourBarCoupling::solve(double phi, double& psi, double& dpsi, double& d2psi,
                            double* d3psi) const {
  const double a = g_.input, b = g_.coupler, c = g_.output, d = g_.ground;
  const double cf = std::cos(phi), sf = std::sin(phi);
  const double A = 2 * c * (a * cf - d), B = 2 * a * c * sf;
  const double C = a * a + c * c + d * d - b * b - 2 * a * d * cf;
  const double r2 = A * A + B * B, disc = r2 - C * C;
  // Locked within 1e-6 rad of a dead point (ψ − atan2(B, A) at 0 or π), where
  // F_ψ = ±√(A² + B² − C²) vanishes: |F_ψ| ≤ 1e-6 √(A² + B²).
  if (!(disc > 1e-12 * r2)) return false;
  psi = std::atan2(B, A) + g_.branch * std::acos(C / std::sqrt(r2));
  const double cp = std::cos(psi), sp = std::sin(psi);
  const double dA = -2 * a * c * sf, dB = 2 * a * c * cf, dC = 2 * a * d * sf;
  const double d2A = -2 * a * c * cf, d2B = -2 * a * c * sf, d2C = 2 * a * d * cf;
  const double F_psi = -A * sp + B * cp, F_phi = dA * cp + dB * sp - dC;
  const double F_phiphi = d2A * cp + d2B * sp - d2C, F_phipsi = -dA * sp + dB * cp;
  const double F_psipsi = -A * cp - B * sp;
  dpsi = -F_phi / F_psi;
  d2psi = -(F_phiphi + 2 * F_phipsi * dpsi + F_psipsi * dpsi * dpsi) / F_psi;
  if (!d3psi) return true;
  // The third total derivative of F(φ, ψ(φ)) = 0:
  //   F_φφφ + 3 F_φφψ ψ' + 3 F_φψψ ψ'² + F_ψψψ ψ'³ + 3 (F_φψ + F_ψψ ψ') ψ'' + F_ψ ψ''' = 0.
  const double d3A = 2 * a * c * sf, d3B = -2 * a * c * cf, d3C = -2 * a * d * sf;
  const double F_3phi = d3A * cp + d3B * sp - d3C, F_2phipsi = -d2A * sp + d2B * cp;
  const double F_phi2psi = -dA * cp - dB * sp, F_3psi = A * sp - B * cp;
  *d3psi = -(F_3phi + 3 * F_2phipsi * dpsi + 3 * F_phi2psi * dpsi * dpsi +
             F_3psi * dpsi * dpsi * dpsi + 3 * (F_phipsi + F_psipsi * dpsi) * d2psi) /
           F_psi;
  return true;
}

bool FourBarCoupling::evaluate(std::span<const double> x, double& f, std::span<double> df,
                               std::span<double> d2f) const {
  double psi, dpsi, d2psi;
  if (!solve(g_.input_offset + g_.input_sign * x[0], psi, dpsi, d2psi)) return false;
  f = g_.output_sign * wrap(psi - g_.output_offset);
  df[0] = g_.output_sign * dpsi * g_.input_sign;
  d2f[0] = g_.output_sign * d2psi * g_.input_sign * g_.input_sign;
  return true;
}

void FourBarCoupling::third_derivatives(std::span<const double> x, std::span<double> d3f) const {
  double psi, dpsi, d2psi, d3psi = NAN;  // (NaN where evaluate is false)
  solve(g_.input_offset + g_.input_sign * x[0], psi, dpsi, d2psi, &d3psi);
  d3f[0] = g_.output_sign * d3psi * g_.input_sign * g_.input_sign * g_.input_sign;
}

std::optional<double> FourBarCoupling::output_angle_at_zero(Geometry g) {
  g.output_offset = 0;
  g.output_sign = 1;
  double psi, dpsi, d2psi;
  if (!FourBarCoupling(g).solve(g.input_offset, psi, dpsi, d2psi)) return std::nullopt;
  return wrap(psi);
}

double FourBarCoupling::closure_residual(double theta_in) const {
  double psi, dpsi, d2psi;
  const double phi = g_.input_offset + g_.input_sign * theta_in;
  if (!solve(phi, psi, dpsi, d2psi)) return INFINITY;
  const double ex = g_.input * std::cos(phi) - g_.ground - g_.output * std::cos(psi);
  const double ey = g_.input * std::sin(phi) - g_.output * std::sin(psi);
  return std::hypot(ex, ey) - g_.coupler;
}

std::optional<double> FourBarCoupling::lock_angle(double lo, double hi) const {
  const auto ok = [&](double t) {
    double psi, dpsi, d2psi;
    return solve(g_.input_offset + g_.input_sign * t, psi, dpsi, d2psi);
  };
  constexpr int kSamples = 4096;
  double last_ok = lo;
  if (!ok(lo)) return lo;
  for (int k = 1; k <= kSamples; ++k) {
    const double t = lo + (hi - lo) * k / kSamples;
    if (ok(t)) {
      last_ok = t;
      continue;
    }
    double good = last_ok, bad = t;  // bisection to the boundary
    while (std::abs(bad - good) > 1e-9) {
      const double mid = 0.5 * (good + bad);
      (ok(mid) ? good : bad) = mid;
    }
    return bad;
  }
  return std::nullopt;
}

std::string LinearCoupling::form() const {
  std::string r = "linear (ratios";
  for (double k : ratios_) r += " " + format_number(k);
  return r + ", offset " + format_number(offset_) + ")";
}

std::string PolynomialCoupling::form() const {
  return "polynomial (" + std::to_string(terms_.size()) + " terms)";
}

std::string SplineCoupling::form() const {
  return "natural cubic spline (" + std::to_string(x_.size()) + " points, θ_in " +
         format_number(x_.front()) + " to " + format_number(x_.back()) + ")";
}

std::string FourBarCoupling::form() const {
  return "four-bar (ground " + format_number(g_.ground) + ", input " + format_number(g_.input) +
         ", coupler " + format_number(g_.coupler) + ", output " + format_number(g_.output) +
         ", branch " + std::to_string(g_.branch) + ")";
}

}  // namespace femdyn
