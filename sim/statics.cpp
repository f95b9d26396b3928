#include "sim/statics.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "compile/compile.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/arguments.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"

namespace femdyn {

namespace {

// The spec with its applied loads (gravity, loads, `extra`) scaled by λ.
MechanismSpec scaled(const MechanismSpec& spec, const std::vector<LoadSpec>& extra, double lambda) {
  MechanismSpec s = spec;
  s.gravity *= lambda;
  s.loads.insert(s.loads.end(), extra.begin(), extra.end());
  for (LoadSpec& l : s.loads) l.force *= lambda, l.torque *= lambda;
  return s;
}

// One model at one λ, with what Newton needs.
struct Problem {
  Model model;
  Workspace ws;
  std::unique_ptr<DerivativeWorkspace> d;  // null where the derivatives do not cover the model
  VecX tau;                                // λ τ
  VecX zero;

  Problem(Model m, const VecX& tau_full, double lambda)
      : model(std::move(m)), ws(model), zero(VecX::Zero(model.n())) {
    if (derivatives_unsupported(model).empty()) d = std::make_unique<DerivativeWorkspace>(model);
    tau = tau_full.size() ? VecX(lambda * tau_full) : zero;
  }
  // r(q) = λ τ − τ_id(q, 0, 0); also the magnitude |τ_id|∞ into `forces`.
  VecX residual(const VecX& q, double& forces) {
    inverse_dynamics(model, ws, q, zero, zero);
    forces = ws.tau.cwiseAbs().maxCoeff();
    return tau - ws.tau;
  }
  // ∂τ_id/∂q in the chart around q: analytic, else by central differences.
  MatX stiffness(const VecX& q) {
    if (d) {
      inverse_dynamics_derivatives(model, ws, *d, q, zero, zero);
      return d->dtau_dq;
    }
    const int n = model.n();
    MatX K(n, n);
    for (int j = 0; j < n; ++j) {
      const double h = 1e-6 * (flat_model(model) ? std::max(1.0, std::abs(q[j])) : 1.0);
      inverse_dynamics(model, ws, integrate_posture(model, q, VecX::Unit(n, j) * h), zero, zero);
      const VecX plus = ws.tau;
      inverse_dynamics(model, ws, integrate_posture(model, q, VecX::Unit(n, j) * -h), zero, zero);
      K.col(j) = (plus - ws.tau) / (2 * h);
    }
    return K;
  }
};

// Newton at one λ from q: true when |r|∞ ≤ tolerance × scale; q and the counts updated.
bool newton(Problem& p, const StaticsOptions& o, VecX& q, StaticsResult& out, std::string& why) {
  bool singular = false;
  double forces = 0;
  VecX r = p.residual(q, forces);
  out.scale = std::max({out.scale, forces, p.tau.size() ? p.tau.cwiseAbs().maxCoeff() : 0.0});
  for (int it = 0; it <= o.max_iterations; ++it) {
    const double norm = r.cwiseAbs().maxCoeff();
    if (!std::isfinite(norm)) {
      why = "the residual is NaN or Inf";
      return false;
    }
    if (norm <= o.tolerance * out.scale) {
      out.residual = norm;
      return true;
    }
    if (it == o.max_iterations) break;
    MatX K = p.stiffness(q);
    Eigen::FullPivLU<MatX> lu(K);
    if (lu.rank() < p.model.n()) {
      // Singular here (a pendulum horizontal: gravity's stiffness is 0 there; or a coordinate
      // nothing holds): a Levenberg–Marquardt step (K + μ 1) Δ = r moves along r instead.
      singular = true;
      const double mu = std::max({K.cwiseAbs().maxCoeff(), out.scale, 1e-300});  // (|Δ| ≲ 1)
      K.diagonal().array() += mu;
      lu.compute(K);
    }
    const VecX step = lu.solve(r);
    // Halve the step until the residual falls (at most 20 times).
    double alpha = 1;
    for (int k = 0; k < 20; ++k, alpha /= 2) {
      const VecX trial = integrate_posture(p.model, q, alpha * step);
      double f = 0;
      const VecX rt = p.residual(trial, f);
      if (rt.cwiseAbs().maxCoeff() < norm) {
        q = trial, r = rt;
        out.scale = std::max(out.scale, f);
        break;
      }
    }
    ++out.iterations;
  }
  why = "Newton did not converge in " + std::to_string(o.max_iterations) + " steps" +
        (singular ? " (the stiffness ∂τ/∂q was singular on the way: a coordinate that nothing "
                    "holds, no spring, load or gravity stiffens it)"
                  : "");
  return false;
}

}  // namespace

StaticsResult solve_statics(const MechanismSpec& spec, const StaticsOptions& o) {
  if (!spec.constraints.empty())
    throw ModelError(spec.where + "/constraints",
                     "statics does not take closed loops yet (the constrained equilibrium is not "
                     "written)");
  StaticsResult out;
  const Model first = compile(scaled(spec, o.loads, 0));
  if (o.tau.size() && o.tau.size() != first.n())
    throw ArgumentError("statics: tau has " + std::to_string(o.tau.size()) +
                        " entries, the model " + std::to_string(first.n()));
  if (!first.prescribed.empty())
    throw ModelError(spec.where + "/bodies",
                     "statics: joint '" + first.prescribed[0].joint +
                         "' is prescribed in time (a driven joint); a rest has no time");
  out.q = o.q0.size() ? o.q0 : neutral_posture(first);
  double step = 1;
  std::string why;
  while (out.lambda < 1) {
    const double lambda = std::min(1.0, out.lambda + step);
    Problem p(compile(scaled(spec, o.loads, lambda)), o.tau, lambda);
    VecX q = out.q;
    if (newton(p, o, q, out, why)) {
      out.q = q, out.lambda = lambda, ++out.load_steps;
      step *= 2;
      continue;
    }
    step /= 2;
    if (step < o.min_step) {
      out.status = {false,
                    "no equilibrium found beyond load factor " + format_number(out.lambda) +
                        " (at " + format_number(lambda) + ": " + why +
                        "; the load steps fell below " + format_number(o.min_step) + ")",
                    -1};
      return out;
    }
  }
  return out;
}

}  // namespace femdyn
