// compile() for a mechanism with a nonlinear coupling law (core/model/coupling_level.hpp): the tree
// of every joint is compiled once, kept as Model::tree, and the model's coordinates become the
// joints that no coupling sets.
#pragma once
#include "compile/compile.hpp"
#include "compile/spec.hpp"
#include "core/model/model.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

bool has_coupling_law(const MechanismSpec& spec);
// The law model of `tree` (compiled without couplings): its coupling level from `couplings`
// (linear ones and laws), its routes the law chain.
Model with_coupling_level(Model tree, const std::vector<CouplingSpec>& couplings);
// The tree of bodies, joints and elements with its linear couplings, its routes chosen
// (compile/routes.hpp); compile() checks the finished model.
Model compile_tree(MechanismSpec spec, const CompileOptions& options);
// Passes shared with compile_tree (compile/compile.cpp), run again once the coordinates change:
// the coordinate joints' addresses in q and the names of q's entries (Model::coordinate_joints
// must hold the joints and their v addresses), then C_q and θ0_q from C and θ0.
void lay_out_coordinates(Model& m);
void configuration_coupling(Model& m);
// Each element that spans two bodies (a rod) must keep its length under the model's
// kinematics: checked at the reference posture and 64 seeded postures within the limits;
// otherwise ModelError naming the element, the posture and the change in length.
void check_rigid_spans(const Model& m);
// The distance between the two nodes of an element that spans two bodies, at the body poses
// in ws (after propagate).
double span_length(const ElementEntry& e, const Workspace& ws);

}  // namespace femdyn
