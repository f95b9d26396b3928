// The compile pass for closed loops and two-point springs: each end named in the spec (a frame,
// a body, "world", or a point on a body) becomes an Attachment, each constraint its rows
// (core/model/loop_constraint.hpp), and each spring its parameters, checked (docs/model-format.md).
#pragma once
#include "compile/spec.hpp"
#include "core/model/model.hpp"

namespace femdyn {

void compile_loops(const MechanismSpec& spec, Model& m);

}  // namespace femdyn
