// Loading a mechanism from a file: JSON (docs/model-format.md) into a MechanismSpec,
// then compile() into a Model. Errors are ModelError: "file: /json/pointer: problem".
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "compile/compile.hpp"
#include "core/model/model.hpp"
#include "io/catalog.hpp"
#include "io/params.hpp"

namespace femdyn {

struct LoadOptions {
  std::optional<Vec3> gravity;                          // overrides the model's gravity
  std::string gravity_source = "LoadOptions::gravity";  // names it in messages ("--gravity")
  std::function<void(const std::string&)> warn;  // non-fatal notes (e.g. URDF friction ignored)
  CompileOptions compile;                        // e.g. the routes (compile/compile.hpp)
  bool floating_base = false;       // URDF: a free joint under the root link (io/urdf_loader.hpp)
  bool balance_inertia = false;     // URDF: a non-physical body inertia -> the nearest physical
  bool exact_mesh_inertia = false;  // MJCF: every mesh weighs its solid (io/mjcf_loader.hpp)
};

// Each takes the element types and model plugins it builds from (io/catalog.hpp); femdyn's own,
// and these functions with it, are models/model_files.hpp's.
// A model file: femdyn JSON, or URDF by its extension .urdf (io/urdf_loader.hpp).
MechanismSpec read_spec(const Catalog& catalog, const std::string& path,
                        const LoadOptions& options = {});
MechanismSpec parse_spec(const std::string& text, const std::string& source_name,
                         const Catalog& catalog);
// A parsed JSON model document (plain or {"model": plugin, "params": …}).
MechanismSpec parse_model_json(const Json& root, const std::string& source_name,
                               const Catalog& catalog);
Model load_model(const Catalog& catalog, const std::string& path, const LoadOptions& options = {});
// The bodies and the centreline of one entry of "flexible_bars" (io/flexible_bar.hpp) as the
// JSON format writes it, read and checked as in a file; `where` names it in messages. For
// builders.
struct FlexibleBarSpec {
  std::vector<BodySpec> bodies;
  BarSpec centreline;
};
FlexibleBarSpec parse_flexible_bar(const Catalog& catalog, const Json& bar,
                                   const std::string& where);
// One entry of "couplings" as the JSON format writes it ({"joint", "follows", "ratio" |
// "polynomial" | "spline" | "four_bar", …}), read and checked as in a file; `where` names it in
// messages. For builders that take a coupling in that form (the Python module).
CouplingSpec parse_coupling(const Json& coupling, const std::string& where);
// One entry of "constraints" or "springs" in the same way (its ends by frame, body or
// {"body", "xyz", "rpy"}; a "node" is not known outside a file); `index` names it by default.
ConstraintSpec parse_constraint(const Json& constraint, const std::string& where,
                                std::size_t index);
SpringSpec parse_spring(const Json& spring, const std::string& where, std::size_t index);

// The model document a file describes (a URDF converted, a plugin expanded), as JSON that
// loads back to the same equations: what `femdyn import` writes.
Json model_document(const Catalog& catalog, const std::string& path,
                    const LoadOptions& options = {});
// The robot file whose bodies the model in `path` has: `path` itself for a URDF or MJCF file,
// the file a JSON reference names ({"model": "urdf" | "mjcf", "params": {"file"}}, relative to
// it), "" for any other model. For what reads the robot file's other parts (femdyn view's
// visuals).
std::string robot_file_of(const std::string& path);
// The files a model in `path` is read from, as run inputs: the file itself and the robot file a
// JSON reference names (io/atomic_file.hpp, input_at).
std::vector<std::pair<std::string, std::string>> model_inputs(const std::string& path);

}  // namespace femdyn
