#include "core/loops/assembly.hpp"

#include <algorithm>
#include <cstdio>
#include <limits>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"

namespace femdyn {

namespace {

double largest_residual(const Model& model, const VecX& phi, std::string& worst) {
  if (phi.size() == 0) return 0;
  Eigen::Index i = 0;
  const double r = phi.cwiseAbs().maxCoeff(&i);
  worst = constraint_row_name(model, static_cast<int>(i));
  return r;
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

}  // namespace

AssemblyReport assemble(const Model& model, Workspace& ws, ConstraintKinematics& k, VecX& q,
                        const AssemblyOptions& options) {
  AssemblyReport report;
  const VecX rest = VecX::Zero(model.n());
  Eigen::CompleteOrthogonalDecomposition<MatX> cod;
  cod.setThreshold(kRankTolerance);
  VecX trial;
  constraint_kinematics(model, ws, q, rest, k);
  double norm = k.phi.norm();
  for (; report.iterations < options.max_iterations; ++report.iterations) {
    if (k.phi.cwiseAbs().maxCoeff() <= options.tolerance) break;
    MatX J = k.J;
    for (int held : options.held) J.col(held).setZero();
    cod.compute(J);
    const VecX delta = -cod.solve(k.phi);
    bool fell = false;
    for (double step = 1; step > 1e-3 && !fell; step /= 2) {
      trial = integrate_posture(model, q, step * delta);
      constraint_kinematics(model, ws, trial, rest, k);
      fell = k.phi.norm() < norm;
    }
    if (!fell) break;  // stalled: at round-off, or at a local minimum of |Φ| that is not zero
    q = trial;
    norm = k.phi.norm();
  }
  constraint_kinematics(model, ws, q, rest, k);
  report.residual = largest_residual(model, k.phi, report.worst);
  report.rank = -1;
  if (options.rank) {
    cod.compute(k.J);
    report.rank = static_cast<int>(cod.rank());
    report.redundant = model.constraint_rows - report.rank;
  }
  // Converged, or stalled at the round-off of the mechanism's size (loop_size, and the distances'
  // lengths); a place on the world is known to within the round-off of its world position
  // (ε |o|, below 1e-10 of the size 1e-4 |o|).
  double size = loop_size(model, ws.origin);
  const bool on_world =
      std::any_of(model.constraints.begin(), model.constraints.end(), [](const LoopConstraint& c) {
        return c.type != ConstraintType::Gear && (c.a.body < 0 || c.b.body < 0);
      });
  if (on_world) size = std::max(size, 1e-4 * ws.origin.norm());
  for (const LoopConstraint& c : model.constraints) size = std::max(size, c.length);
  if (report.residual > std::max(options.tolerance, 1e-10 * size))
    report.status = {false,
                     "the loops cannot close from this configuration: after " +
                         std::to_string(report.iterations) + " Newton iterations |Φ| = " +
                         number(report.residual) + " at constraint '" + report.worst +
                         "' (lengths that do not fit, or a guess too far: start nearer)",
                     -1};
  return report;
}

Status project_velocity(const Model& model, Workspace& ws, LoopWorkspace& lws, const VecX& q,
                        VecX& v) {
  mass_matrix(model, ws, q);
  if (Status st = ws.solver.factorize(ws.Ms); !st.ok) return st;
  constraint_kinematics(model, ws, q, v, lws.k);
  factorize_constraint_space(model, ws, lws);
  lws.r.noalias() = -lws.k.J * v;  // S λ = −Φ_q v,  v += Y λ (least squares where redundant
                                   // rows of Φ_q v contradict each other: never a failure)
  if (Status st = solve_constraint_space(model, lws, std::numeric_limits<double>::infinity());
      !st.ok)
    return st;
  v.noalias() += lws.Y * lws.lambda;
  return {};
}

StateAssembly assemble_state(const Model& model, VecX& q, VecX& v, const AssemblyOptions& options) {
  Workspace ws(model);
  LoopWorkspace lws(model);
  StateAssembly s;
  s.assembly = assemble(model, ws, lws.k, q, options);
  if (!s.assembly.status.ok) return s;
  const VecX v0 = v;
  s.assembly.status = project_velocity(model, ws, lws, q, v);
  s.velocity_change = (v - v0).cwiseAbs().maxCoeff();
  return s;
}

}  // namespace femdyn
