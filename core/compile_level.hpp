// compile() for a mechanism with a nonlinear coupling law (core/coupling_level.hpp): the tree
// of every joint is compiled twice from the spec (once as Model::tree, once as the model
// itself), and the model's coordinates become the joints that no coupling sets.
#pragma once
#include "core/model.hpp"

namespace femdyn {

bool has_coupling_law(const MechanismSpec& spec);
Model compile_with_coupling_level(MechanismSpec spec);

}  // namespace femdyn
