// Fixed-step integrators (core/integrator.hpp): steps of dt, the last one before an output time
// shortened to land on it. Buffers are sized at construction; a step allocates nothing.
#pragma once
#include <algorithm>
#include <array>

#include "core/integrator.hpp"

namespace femdyn {

class FixedStep : public Integrator {
 protected:
  FixedStep(const Model& model, const FixedStepOptions& options, Actuation tau);
  void start() override {}
  Status advance(double t_out) override;
  Status one_step() override { return advance(std::min(t_ + options_.dt, t_stop_)); }
  // One step of length h from (t_, y_) into y_next; y_ is replaced only if the step succeeds.
  virtual Status take_step(double h) = 0;
  FixedStepOptions options_;
  VecX y_next_;
};

// Classical RK4:  k_i = f(t + c_i h, y + h a_i k_{i−1}),  c = a = (0, ½, ½, 1),
//                 y_next = y + h/6 (k1 + 2 k2 + 2 k3 + k4).
class Rk4 final : public FixedStep {
 public:
  Rk4(const Model& model, const FixedStepOptions& options, Actuation tau = {});
  IntegratorKind kind() const override { return IntegratorKind::Rk4; }

 private:
  Status take_step(double h) override;
  std::array<VecX, 4> k_;
  VecX stage_;
};

// Semi-implicit (symplectic) Euler:  q̇_next = q̇ + h q̈(t, q, q̇),  q_next = q + h q̇_next,
// W_next = W + h P_nc(t, q, q̇). Symplectic for conservative forces: its energy error stays
// bounded over long runs instead of drifting.
class SymplecticEuler final : public FixedStep {
 public:
  SymplecticEuler(const Model& model, const FixedStepOptions& options, Actuation tau = {});
  IntegratorKind kind() const override { return IntegratorKind::Euler; }

 private:
  Status take_step(double h) override;
  VecX f_;
};

}  // namespace femdyn
