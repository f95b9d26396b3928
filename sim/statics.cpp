#include "sim/statics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "compile/compile.hpp"
#include "core/derivatives/constraint_derivatives.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/assembly.hpp"
#include "core/loops/constraint_kinematics.hpp"
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

// The closed loops' equilibrium: the balance with the constraint forces Φ_qᵀ μ, on Φ = 0,
//   F(q, μ) = (r(q) + Φ_qᵀ μ, Φ(q)) = 0,
//   ∂F = [[−K + G, Φ_qᵀ], [Φ_q, 0]],  K = ∂τ_id/∂q,  G = ∂(Φ_qᵀ μ)/∂q at μ held
// (core/derivatives/constraint_derivatives.hpp). Each Newton step (the least-norm solution:
// redundant equations leave μ's part along them free) is followed by the projection of q back
// onto Φ = 0 (assemble_state) and μ by least squares there, so that every iterate is a
// configuration of the mechanism and only the balance r + Φ_qᵀ μ, the force no constraint
// carries, is driven to 0.
struct LoopStatics {
  Problem& p;
  ConstraintKinematics k;
  std::unique_ptr<ConstraintDerivatives> cd;
  VecX mu;  // at the last accepted q

  explicit LoopStatics(Problem& problem) : p(problem), k(problem.model) {
    if (p.d) cd = std::make_unique<ConstraintDerivatives>(p.model);
  }
  // q projected onto Φ = 0, μ = argmin |r + Φ_qᵀ μ| there, and that balance F₁ (∞ if q does
  // not assemble); the largest force into `forces`.
  double balance(VecX& q, VecX& mu_out, VecX& F1, double& forces) {
    VecX v = VecX::Zero(p.model.n());
    if (!assemble_state(p.model, q, v, {.rank = false}).assembly.status.ok)
      return std::numeric_limits<double>::infinity();
    const VecX r = p.residual(q, forces);
    constraint_kinematics(p.model, p.ws, q, p.zero, k);
    mu_out = MatX(k.J.transpose()).completeOrthogonalDecomposition().solve(-r);
    const VecX f = k.J.transpose() * mu_out;
    forces = std::max(forces, f.cwiseAbs().maxCoeff());
    F1 = r + f;
    return F1.cwiseAbs().maxCoeff();
  }
  // ∂F at (q, μ): analytic where the derivatives cover the model, else by differences of F₁.
  MatX jacobian(const VecX& q) {
    const int n = p.model.n(), m = p.model.constraint_rows;
    MatX A = MatX::Zero(n + m, n + m);
    constraint_kinematics(p.model, p.ws, q, p.zero, k);
    const MatX J = k.J;
    A.topRightCorner(n, m) = J.transpose();
    A.bottomLeftCorner(m, n) = J;
    if (cd) {
      A.topLeftCorner(n, n) = -p.stiffness(q);  // (leaves d's recursion at (q, 0, 0))
      constraint_derivatives(p.model, p.ws, *p.d, mu, 0.0, *cd);
      A.topLeftCorner(n, n) += cd->G;
      return A;
    }
    double forces = 0;
    const auto F1 = [&](const VecX& x) {  // r + Φ_qᵀ μ at x, μ held
      constraint_kinematics(p.model, p.ws, x, p.zero, k);
      return VecX(p.residual(x, forces) + k.J.transpose() * mu);
    };
    for (int j = 0; j < n; ++j) {
      const double h = 1e-6 * (flat_model(p.model) ? std::max(1.0, std::abs(q[j])) : 1.0);
      A.col(j).head(n) = (F1(integrate_posture(p.model, q, VecX::Unit(n, j) * h)) -
                          F1(integrate_posture(p.model, q, VecX::Unit(n, j) * -h))) /
                         (2 * h);
    }
    return A;
  }
};

// Newton on the loops at one λ from q (on them): true when |r + Φ_qᵀ μ|∞ ≤ tolerance × scale;
// q, μ and the counts updated.
bool newton_loops(Problem& p, const StaticsOptions& o, VecX& q, VecX& mu, StaticsResult& out,
                  std::string& why) {
  const int n = p.model.n();
  LoopStatics loops(p);
  VecX F1;
  double forces = 0;
  double e = loops.balance(q, loops.mu, F1, forces);
  out.scale = std::max({out.scale, forces, p.tau.size() ? p.tau.cwiseAbs().maxCoeff() : 0.0});
  for (int it = 0; it <= o.max_iterations; ++it) {
    if (!std::isfinite(e)) {
      why = "the residual is NaN or Inf, or the loops do not close";
      return false;
    }
    if (e <= o.tolerance * out.scale) {
      out.residual = e;
      out.constraint_residual = loops.k.phi.cwiseAbs().maxCoeff();
      mu = loops.mu;
      return true;
    }
    if (it == o.max_iterations) break;
    MatX A = loops.jacobian(q);
    VecX rhs = VecX::Zero(A.rows());
    rhs.head(n) = -F1;
    // Newton's step, halved until the balance falls (at most 20 times); where none does (a
    // direction the loads barely hold), a Levenberg–Marquardt step with μ_LM the largest
    // |∂F₁/∂q| or force on the q block, as the tree's.
    bool fell = false;
    for (int attempt = 0; attempt < 2 && !fell; ++attempt) {
      if (attempt == 1)
        A.topLeftCorner(n, n).diagonal().array() -=
            std::max({A.topLeftCorner(n, n).cwiseAbs().maxCoeff(), out.scale, 1e-300});
      const VecX step = A.completeOrthogonalDecomposition().solve(rhs);
      double alpha = 1;
      for (int k = 0; k < 20 && !fell; ++k, alpha /= 2) {
        VecX trial = integrate_posture(p.model, q, alpha * step.head(n)), trial_mu, Ft;
        double f = 0;
        const double et = loops.balance(trial, trial_mu, Ft, f);
        if ((fell = et < e)) {
          q = trial, loops.mu = trial_mu, F1 = Ft, e = et;
          out.scale = std::max(out.scale, f);
        }
      }
    }
    ++out.iterations;
  }
  why = "Newton did not converge in " + std::to_string(o.max_iterations) +
        " steps on the closed loops";
  return false;
}

}  // namespace

StaticsResult solve_statics(const MechanismSpec& spec, const StaticsOptions& o) {
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
  const bool loops = !first.constraints.empty();
  if (loops) {  // the start on the loops (Newton's least-norm steps)
    VecX v = VecX::Zero(first.n());
    if (const StateAssembly s = assemble_state(first, out.q, v); !s.assembly.status.ok) {
      out.status = {false, "the loops do not close from the start: " + s.assembly.status.message,
                    -1};
      return out;
    }
    out.multipliers = VecX::Zero(first.constraint_rows);
  }
  double step = 1;
  std::string why;
  while (out.lambda < 1) {
    const double lambda = std::min(1.0, out.lambda + step);
    Problem p(compile(scaled(spec, o.loads, lambda)), o.tau, lambda);
    VecX q = out.q, mu = out.multipliers;
    if (loops ? newton_loops(p, o, q, mu, out, why) : newton(p, o, q, out, why)) {
      out.q = q, out.multipliers = mu, out.lambda = lambda, ++out.load_steps;
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
