// A model file's JSON text read safely: its nesting depth and number of bodies bounded by one
// linear pass before it is parsed (core/model/limits.hpp), malformed JSON named by line and column.
#pragma once
#include <string>

#include "io/params.hpp"

namespace femdyn {

// The text as JSON, or a ModelError naming `source` and the problem.
Json parse_json(const std::string& text, const std::string& source);

}  // namespace femdyn
