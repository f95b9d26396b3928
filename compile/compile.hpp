// compile(): a mechanism as described (compile/spec.hpp) into an immutable Model
// (core/model/model.hpp), by the passes of compile/compile.cpp.
#pragma once
#include "compile/spec.hpp"
#include "core/model/model.hpp"

namespace femdyn {

// What compile() may be told. A compiled Model is never changed afterwards: a route other than
// the one compile() chooses is asked for here (tests and benchmarks compare routes).
struct CompileOptions {
  RouteChoice routes;  // for the model and, with a nonlinear coupling law, its tree
  // M^s regular at sampled states (compile/correlation.hpp), else ModelError. Off for what
  // describes a model without its dynamics (info, import, view), which report the problem.
  bool check_mass = true;
};

// Compiles a spec; throws ModelError naming spec `where` labels on bad input.
Model compile(MechanismSpec spec, const CompileOptions& options = {});

}  // namespace femdyn
