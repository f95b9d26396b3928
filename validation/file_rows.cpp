#include "validation/file_rows.hpp"

#include <optional>

#include "io/mjcf_loader.hpp"
#include "io/model_format.hpp"

namespace femdyn::validation {
namespace {

#ifdef FEMDYN_WITH_MUJOCO
// The MJCF import against MuJoCo's own compile of the file.
void add_mjcf_row(ValidationReport& r, const Model& model, const std::string& path,
                  const ValidationOptions& o, const LoadOptions& load) {
  std::string why;
  const MjcfMassNotes mass = read_mjcf(path, {.balance_inertia = load.balance_inertia}).mass_notes;
  // MuJoCo 2.2 has no legacy solid of a non-convex mesh: both sides then weigh every mesh by its
  // exact solid, said in a note.
  std::optional<Model> exact;
  if (!mass.not_solid.empty()) {
    LoadOptions same = load;
    same.warn = [](const std::string&) {};  // said once, by the first load
    same.exact_mesh_inertia = true;
    exact = load_model(path, same);
    r.notes.push_back("compared with MuJoCo with every mesh weighed by its exact solid (" +
                      std::to_string(mass.not_solid.size()) +
                      " geoms of non-convex meshes, whose legacy inertia MuJoCo 2.2 does not "
                      "compute): the rest of the model is the one checked above");
  }
  auto e = validate_mjcf_import(exact ? *exact : model, path, mass.mesh_geoms, mass.full_inertias,
                                o, why);
  if (!e) {
    r.notes.push_back("not compared with MuJoCo's compile of the file: " + why);
    return;
  }
  r.quantities.push_back(*e);
  if (!why.empty()) r.notes.push_back(why);
  if (!r.failure.empty()) {  // the Simbody twin could not hold it: MuJoCo's row stands alone
    r.notes.push_back("compared with MuJoCo only: " + r.failure);
    r.trajectory.skipped = "the Simbody twin cannot hold the model (note below)";
    r.failure.clear();
    r.not_comparable = false;
  }
}
#endif

}  // namespace

void add_file_rows(ValidationReport& r, const Model& model, const std::string& path,
                   const ValidationOptions& o, const LoadOptions& load) {
  if (is_urdf_path(path) && r.failure.empty()) {
    // The import itself, against a Simbody model read straight from the XML.
    std::string failure;
    r.quantities.push_back(validate_urdf_import(model, path, o, failure, load.balance_inertia));
    if (!failure.empty()) r.failure = failure;
  }
#ifdef FEMDYN_WITH_MUJOCO
  if (is_mjcf_path(path)) add_mjcf_row(r, model, path, o, load);
#endif
}

}  // namespace femdyn::validation
