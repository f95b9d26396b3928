// The node level and the correlation table N_m (paper §IV): which transition coordinates u
// the mechanism has, how each element's local DOFs map onto them, and the assembled system
// lumped mass M and constant nodal forces F.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "compile/spec.hpp"
#include "core/model/model.hpp"

namespace femdyn {

// Fills m.nodes, m.dofs, m.node_dof, m.body_rot_dof, m.elements (moved out of spec),
// m.left_out, m.M, m.F_constant, m.torques. body_of_spec maps spec body index -> model body.
void build_node_level(MechanismSpec& spec, const std::vector<int>& body_of_spec, Model& m);

// Why M^s is singular at the reference state or a seeded random state, or nothing: `where` the
// joint of the first coordinate whose pivot vanishes, `message` the solver's account, `inert`
// with `list_inert` every coordinate with a zero diagonal entry there (it moves no inertia at
// all), when a dense M^s is small enough to form (n ≤ 4000).
struct MassMatrixProblem {
  std::string where, message;
  std::vector<std::string> inert;
};
std::optional<MassMatrixProblem> mass_matrix_problem(const Model& m, bool list_inert = false);
// Throws ModelError(where, message) for the problem above.
void check_mass_matrix(const Model& m);

// Seeded random generalized coordinates used for structural checks.
std::vector<VecX> sample_states(const Model& m, int count);

}  // namespace femdyn
