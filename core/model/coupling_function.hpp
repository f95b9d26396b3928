// The law of one coupled joint, θ_out = f(x), x = the θ of the joints it follows, with its
// exact gradient and Hessian (the coupling level θ = g(q) chains them:
// core/model/coupling_level.hpp). Forms (docs/model-format.md#couplings): linear, polynomial,
// natural cubic spline, four-bar.
#pragma once
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace femdyn {

class CouplingFunction {
 public:
  virtual ~CouplingFunction() = default;
  virtual int arity() const = 0;  // how many joints it follows
  // f(x) into `f`, ∂f/∂x_k into df[k], ∂²f/∂x_k∂x_l into d2f[k * arity + l]. False where f is
  // not defined (a linkage that cannot assemble there); the outputs are then unspecified.
  virtual bool evaluate(std::span<const double> x, double& f, std::span<double> df,
                        std::span<double> d2f) const = 0;
  // ∂³f/∂x_k∂x_l∂x_p into d3f[(k * arity + l) * arity + p], where evaluate is true (the analytic
  // derivatives of the dynamics chain them through the level: core/derivatives/coupling.hpp).
  virtual void third_derivatives(std::span<const double> x, std::span<double> d3f) const = 0;
  // The law's form and parameters for reports, e.g. "four-bar (ground 0.03, …)".
  virtual std::string form() const = 0;
  // The first x in [lo, hi] of a one-argument law where it is not defined (to 1e-9), or
  // nullopt: checked by compile() over the followed joint's range.
  virtual std::optional<double> lock_angle(double /*lo*/, double /*hi*/) const {
    return std::nullopt;
  }
};

// f = Σ_k ratio_k x_k + offset (today's coupling).
class LinearCoupling final : public CouplingFunction {
 public:
  std::string form() const override;
  LinearCoupling(std::vector<double> ratios, double offset)
      : ratios_(std::move(ratios)), offset_(offset) {}
  int arity() const override { return static_cast<int>(ratios_.size()); }
  bool evaluate(std::span<const double> x, double& f, std::span<double> df,
                std::span<double> d2f) const override;
  void third_derivatives(std::span<const double> x, std::span<double> d3f) const override;

 private:
  std::vector<double> ratios_;
  double offset_;
};

// f = Σ_t c_t Π_k x_k^{p_tk}: a polynomial in one or more coordinates.
class PolynomialCoupling final : public CouplingFunction {
 public:
  std::string form() const override;
  struct Term {
    double coefficient = 0;
    std::vector<int> powers;  // one per followed joint, >= 0
  };
  PolynomialCoupling(int arity, std::vector<Term> terms)
      : arity_(arity), terms_(std::move(terms)) {}
  int arity() const override { return arity_; }
  bool evaluate(std::span<const double> x, double& f, std::span<double> df,
                std::span<double> d2f) const override;
  void third_derivatives(std::span<const double> x, std::span<double> d3f) const override;

 private:
  int arity_;
  std::vector<Term> terms_;
};

// The natural cubic spline through (x_i, y_i), x strictly increasing, at least 2 points: C²,
// with S'' = 0 at both ends, continued as straight lines beyond them (still C²).
class SplineCoupling final : public CouplingFunction {
 public:
  std::string form() const override;
  SplineCoupling(std::vector<double> x, std::vector<double> y);  // sizes checked by the caller
  int arity() const override { return 1; }
  bool evaluate(std::span<const double> x, double& f, std::span<double> df,
                std::span<double> d2f) const override;
  void third_derivatives(std::span<const double> x, std::span<double> d3f) const override;

 private:
  std::vector<double> x_, y_, m_;  // m_: S'' at the knots
};

// The planar four-bar: ground link d between the input pivot O and the output pivot P, input
// crank a at angle φ (from O→P, about the joints' common axis), coupler b, output rocker c at
// angle ψ at P. Loop closure |O + a e(φ) − P − c e(ψ)| = b, solved in closed form:
//   A cos ψ + B sin ψ = C,  A = 2c(a cos φ − d),  B = 2ac sin φ,  C = a² + c² + d² − b² − 2ad cos φ
//   ψ = atan2(B, A) + σ acos(C / √(A² + B²)),   σ = ±1 the assembly branch,
// with ψ', ψ'' and ψ''' by implicit differentiation of F(φ, ψ) = A cos ψ + B sin ψ − C = 0. The
// joint angles map as φ = φ0 + s_in θ_in and θ_out = s_out (ψ − ψ0).
class FourBarCoupling final : public CouplingFunction {
 public:
  std::string form() const override;
  struct Geometry {
    double ground = 0, input = 0, coupler = 0, output = 0;  // d, a, b, c (> 0)
    int branch = 1;                                         // σ
    double input_offset = 0, input_sign = 1;                // φ0, s_in
    double output_offset = 0, output_sign = 1;              // ψ0, s_out
  };
  explicit FourBarCoupling(const Geometry& g) : g_(g) {}
  int arity() const override { return 1; }
  bool evaluate(std::span<const double> x, double& f, std::span<double> df,
                std::span<double> d2f) const override;
  void third_derivatives(std::span<const double> x, std::span<double> d3f) const override;
  // The loop-closure residual |O + a e(φ) − P − c e(ψ)| − b at θ_in, for tests.
  double closure_residual(double theta_in) const;
  // The first input angle in [lo, hi] (finite) where the linkage cannot assemble or locks (its
  // reaches a dead point: ψ − atan2(B, A) at 0 or π, F_ψ = 0), to 1e-9 rad; nullopt if it
  // moves freely.
  std::optional<double> lock_angle(double lo, double hi) const override;
  const Geometry& geometry() const { return g_; }
  // ψ at θ_in = 0 (the default output_offset: θ_out = 0 there), or nullopt where the linkage
  // cannot assemble at θ_in = 0. Ignores g's output offset and sign.
  static std::optional<double> output_angle_at_zero(Geometry g);

 private:
  // ψ, ψ', ψ'' (and with d3psi ψ''') at φ; false where it cannot assemble or locks.
  bool solve(double phi, double& psi, double& dpsi, double& d2psi, double* d3psi = nullptr) const;
  Geometry g_;
};

}  // namespace femdyn
