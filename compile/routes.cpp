#include "compile/routes.hpp"

#include "core/dynamics/equations.hpp"
#include "core/dynamics/span_inertia.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/model/errors.hpp"
#include "core/workspace/mass_pattern.hpp"

namespace femdyn {
namespace {

// A route asked for: any reference route, a body-level one only where it was chosen (exact).
void take_asked_routes(Model& m, const RouteChoice& asked) {
  const auto refuse = [&](const char* route) {
    throw ModelError(m.where, std::string("the ") + route +
                                  " route is not exact for this model (compile options)");
  };
  if (asked.mass) {
    if (*asked.mass == MassRoute::Composite && m.mass_route != MassRoute::Composite)
      refuse("composite mass");
    m.mass_route = *asked.mass;
  }
  if (asked.force) {
    if (*asked.force == ForceRoute::Bodies && m.force_route != ForceRoute::Bodies)
      refuse("body-level force");
    m.force_route = *asked.force;
  }
  if (asked.dynamics) {
    if (*asked.dynamics == DynamicsRoute::Articulated &&
        m.dynamics_route != DynamicsRoute::Articulated)
      refuse("articulated");
    m.dynamics_route = *asked.dynamics;
  }
}

// The tree routes of a model without a coupling law.
void choose_tree_routes(Model& m, const RouteChoice& asked) {
  // Elements spanning bodies that use only their nodes' translations (a coupler rod) keep the
  // rest of the tree on the body-level routes, their own terms added
  // (core/dynamics/span_inertia.hpp), where the rest is exact and there is no coupling level to map
  // them through.
  const bool spans_on_bodies = !m.condensable && m.condensable_off_spans &&
                               m.velocity_forces_rigid && m.identity_coupling &&
                               span_inertia_unsupported(m).empty();
  const bool body_level = m.condensable || spans_on_bodies;
  // M^s by composite inertias wherever the body-level form is exact: measured faster than
  // Tᵀ (M T) on every model, from the 1-DOF pendulum up (docs/performance.md).
  m.mass_route = body_level ? MassRoute::Composite : MassRoute::Transform;
  // h and τ: the body-level recursion is exact under the same conditions (couplings are
  // linear), and it is O(bodies) instead of O(N_u) (measured faster on every model).
  m.force_route = body_level && m.velocity_forces_rigid ? ForceRoute::Bodies : ForceRoute::Nodes;
  // The articulated recursion pivots on each joint's block of rates
  // (core/dynamics/articulated.hpp); couplings (C ≠ I) it cannot eliminate joint by joint.
  m.dynamics_route = m.condensable && m.velocity_forces_rigid && m.identity_coupling
                         ? DynamicsRoute::Articulated
                         : DynamicsRoute::Cholesky;
  take_asked_routes(m, asked);
  // The spanning masses where a body-level route carries them (never with the coupling level).
  const bool carried = m.mass_route == MassRoute::Composite || m.force_route == ForceRoute::Bodies;
  m.spanning_masses = spans_on_bodies && carried ? spanning_masses(m) : std::vector<SpanningMass>{};
}

// The solver of the Cholesky route: a tree factorisation where the pattern is a tree, CHOLMOD
// for a large sparse one, else dense.
void analyse_mass_pattern(Model& model) {
  MassPattern& mp = model.mass_pattern;
  mp = MassPattern{};
  mp.coordinate_parent = coordinate_tree(model);
  if (!mp.coordinate_parent.empty()) {
    mp.solver = SolverKind::Tree;  // no fill, at any size
    return;
  }
  // Dense Cholesky is faster below a few dozen coordinates whatever the fill.
  if (model.n() < 64 || mass_matrix_fill(model) >= 0.3) return;
  mp.solver = SolverKind::Sparse;
  mp.sparse_order = fill_reducing_order(coordinate_pattern(model));
}

}  // namespace

void choose_routes(Model& m, const RouteChoice& asked) {
  if (m.coupling_level) {
    // The law chain (core/dynamics/coupling_chain.hpp) reduces the tree's equations, its own
    // routes chosen when it was compiled, and factorises the reduced M^s densely.
    m.dynamics_route = DynamicsRoute::Cholesky;
    m.mass_pattern = MassPattern{};
  } else {
    choose_tree_routes(m, asked);
    analyse_mass_pattern(m);
  }
  m.routes = choose_equation_routes(m);
  if (m.constraints.empty()) {
    m.routes.mechanism_forward_dynamics = tree_mechanism_forward_dynamics;
    m.routes.names.mechanism = m.routes.names.forward;
  } else {
    m.routes.mechanism_forward_dynamics = closed_mechanism_forward_dynamics;
    m.routes.names.mechanism =
        "the constrained q̈ of M^s q̈ + h = Q + Φ_qᵀ λ, Φ_q q̈ = −Φ̇_q q̇ (S = Φ_q (M^s)⁻¹ Φ_qᵀ by "
        "pivoted Cholesky)";
  }
}

void provisional_routes(Model& m) { m.routes = choose_equation_routes(m); }

}  // namespace femdyn
