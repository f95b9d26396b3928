// The rows of `femdyn validate` (and of Python's femdyn.validate) that check a model against the
// robot file it was read from: a URDF's import against a Simbody model read straight from the
// XML (validate_urdf_import), an MJCF's against MuJoCo's own compile (validate_mjcf_import,
// with FEMDYN_WITH_MUJOCO; where the Simbody twin cannot hold the model, MuJoCo's comparison
// stands alone, said in a note). One place, so that every door answers the same.
#pragma once
#include <string>

#include "core/model/model.hpp"
#include "models/model_files.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {

// Adds them to `r` for the model `model` loaded from `path` with `load` (its gravity, floating
// base, inertia balancing); nothing for a JSON file.
void add_file_rows(ValidationReport& r, const Model& model, const std::string& path,
                   const ValidationOptions& o, const LoadOptions& load);

}  // namespace femdyn::validation
