// Loading a mechanism from a file: JSON (docs/model-format.md) into a MechanismSpec,
// then compile() into a Model. Errors are ModelError: "file: /json/pointer: problem".
#pragma once
#include <optional>
#include <string>

#include "core/model.hpp"

namespace femdyn {

struct LoadOptions {
  std::optional<Vec3> gravity;  // overrides the model's gravity
};

MechanismSpec read_spec(const std::string& path);
MechanismSpec parse_spec(const std::string& text, const std::string& source_name);
Model load_model(const std::string& path, const LoadOptions& options = {});

}  // namespace femdyn
