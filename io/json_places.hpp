// The places of a femdyn JSON model (docs/model-format.md): the nodes bodies name, and what is
// fixed on a body by a point or a node (the ends of constraints and springs, frames and loads),
// read from the document's "constraints", "springs", "frames" and "loads". Used by
// io/model_loader.cpp.
#pragma once
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "compile/spec.hpp"
#include "io/params.hpp"

namespace femdyn {

// Every body's named nodes as "body/node" (body frame of that body): an element may reach a
// node of another body by that name (an element that spans bodies, docs/model-format.md).
std::map<std::string, Vec3> qualified_nodes(const Json& bodies);

// The bodies' JSON objects by name (a list: a duplicate name is reported by compile()).
using BodiesByName = std::map<std::string, std::vector<const Json*>>;
BodiesByName bodies_by_name(const Json& bodies);

// {"name", "type", "a", "b", "normal" | "direction" | "length"} or a gear {"name", "type":
// "gear", "joint", "follows", "ratio", "offset"} (docs/model-format.md#constraints).
ConstraintSpec read_constraint(const Params& p, const BodiesByName& bodies, std::size_t index);
// {"name", "a", "b", "stiffness", "rest_length", "damping"}: a two-point spring-damper.
SpringSpec read_spring(const Params& p, const BodiesByName& bodies, std::size_t index);
// {"name", "body", "xyz" | "node", "rpy"}: a frame on a body, at a point or at one of its nodes.
FrameSpec read_frame(const Params& p, const BodiesByName& bodies);
// {"body", "point" | "node", "force", "torque"}: a constant load on a body.
LoadSpec read_load(const Params& p, const BodiesByName& bodies);

}  // namespace femdyn
