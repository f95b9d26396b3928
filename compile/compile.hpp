// compile(): a mechanism as described (compile/spec.hpp) into an immutable Model
// (core/model.hpp), by the passes of compile/compile.cpp.
#pragma once
#include "compile/spec.hpp"
#include "core/model.hpp"

namespace femdyn {

// Compiles a spec; throws ModelError naming spec `where` labels on bad input.
Model compile(MechanismSpec spec);

}  // namespace femdyn
