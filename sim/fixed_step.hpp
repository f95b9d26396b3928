// Fixed-step integrators (sim/integrator.hpp): steps on the grid t_k = t0 + k dt (times are
// computed, never summed, so no round-off accumulates); an output time between two grid times
// is landed on by a shortened step, and the next step returns to the grid. Buffers are sized
// at construction; a step allocates nothing.
#pragma once
#include <algorithm>
#include <array>

#include "sim/integrator.hpp"

namespace femdyn {

class FixedStep : public Integrator {
 protected:
  FixedStep(const Model& model, const FixedStepOptions& options, Actuation tau);
  void start() override { k_ = 0; }
  Status advance(double t_out) override;
  Status one_step() override;
  Status plan(double t_end) override;
  std::string setting() const override;
  double fixed_dt() const override { return options_.dt; }
  // One step of length h from (t_, y_) into y_next; y_ is replaced only if the step succeeds.
  virtual Status take_step(double h) = 0;
  virtual int evaluations_per_step() const = 0;
  double grid(long k) const { return t0_ + static_cast<double>(k) * options_.dt; }
  FixedStepOptions options_;
  VecX y_next_;
  long k_ = 0;  // the last grid time reached, t_k ≤ t_
};

// Classical RK4:  k_i = f(t + c_i h, y + h a_i k_{i−1}),  c = a = (0, ½, ½, 1),
//                 y_next = y + h/6 (k1 + 2 k2 + 2 k3 + k4).
class Rk4 final : public FixedStep {
 public:
  Rk4(const Model& model, const FixedStepOptions& options, Actuation tau = {});
  IntegratorKind kind() const override { return IntegratorKind::Rk4; }

 private:
  Status take_step(double h) override;
  int evaluations_per_step() const override { return 4; }
  std::array<VecX, 4> k_;
  VecX stage_;
};

// Semi-implicit Euler:  q̇_next = q̇ + h q̈(t, q, q̇),  q_next = q + h q̇_next,
// W_next = W + h P_nc(t, q, q̇). Order 1. In (q, q̇) it is symplectic only where M^s is constant
// (one joint, or prismatic axes): there its energy error stays bounded over long runs. Where
// M^s depends on q (any chain of revolute joints) it is not, and its energy error can grow
// (docs/simulation.md, tests/test_integrators.cpp).
class SymplecticEuler final : public FixedStep {
 public:
  SymplecticEuler(const Model& model, const FixedStepOptions& options, Actuation tau = {});
  IntegratorKind kind() const override { return IntegratorKind::Euler; }

 private:
  Status take_step(double h) override;
  int evaluations_per_step() const override { return 1; }
  VecX f_;
};

}  // namespace femdyn
