// The front door of a model file (io/model_loader.hpp): femdyn JSON, a JSON reference to a URDF
// or MJCF file, or the robot file itself, read into a MechanismSpec and compiled; an error found
// in a robot file's converted document is reported at the robot file's element
// (rethrow_for_robot_file).
#include "compile/compile.hpp"
#include "io/input_file.hpp"
#include "io/json_text.hpp"
#include "io/model_loader.hpp"
#include "io/robot_reference.hpp"

namespace femdyn {

Json model_document(const Catalog& catalog, const std::string& path, const LoadOptions& options) {
  if (is_robot_file(path)) return robot_document(path, options);
  const Json root = parse_json(read_input_file(path), path);
  if (auto ref = robot_reference(path, root, options)) return std::move(ref->first);
  refuse_balance_on_json(path, options);
  (void)parse_model_json(root, path, catalog);  // reports every model error by its path
  return root.contains("model") ? expand_plugin(catalog, root, path) : root;
}

MechanismSpec read_spec(const Catalog& catalog, const std::string& path,
                        const LoadOptions& options) {
  if (!is_robot_file(path) && options.floating_base)
    throw ModelError(path,
                     "--floating-base is for URDF models: a JSON model gives its root body a "
                     "free joint itself (\"joint\": {\"type\": \"free\"}), a URDF "
                     "reference by \"root_joint\": \"free\"");
  if (!is_robot_file(path)) {
    const Json root = parse_json(read_input_file(path), path);
    if (auto ref = robot_reference(path, root, options)) {
      try {
        return parse_model_json(ref->first, ref->second, catalog);
      } catch (const ModelError& e) {
        rethrow_for_robot_file(e, ref->first, ref->second);
      }
    }
    refuse_balance_on_json(path, options);
    return parse_model_json(root, path, catalog);
  }
  const Json doc = model_document(catalog, path, options);
  try {
    return parse_model_json(doc, path, catalog);
  } catch (const ModelError& e) {
    rethrow_for_robot_file(e, doc, path);
  }
}

Model load_model(const Catalog& catalog, const std::string& path, const LoadOptions& options) {
  MechanismSpec spec = read_spec(catalog, path, options);
  if (options.gravity) {
    spec.gravity = *options.gravity;
    spec.gravity_where = spec.where + options.gravity_source;  // (where ends in ": ")
  }
  if (!is_robot_file(path)) return compile(std::move(spec), options.compile);
  try {
    return compile(std::move(spec), options.compile);
  } catch (const ModelError& e) {
    rethrow_for_robot_file(e, model_document(catalog, path, options), path);
  }
}

}  // namespace femdyn
