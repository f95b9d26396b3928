// femdyn import ROBOT.urdf -o ROBOT.json: the femdyn JSON document of a model file.
#include <filesystem>
#include <iostream>

#include "cli/commands.hpp"
#include "io/atomic_file.hpp"
#include "io/output.hpp"
#include "models/model_files.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kImportHelp =
    R"(usage: femdyn import MODEL -o OUT.json [--force] [--gravity gx,gy,gz]     (-o is --output)

Writes the femdyn JSON document of MODEL: a URDF robot converted (each link with an <inertial>
becomes a body with one rigid_body element, its inertia rotated out of the <inertial> frame; a
link with an inertia but zero mass gets a rotary_node; links without <inertial> are massless;
joints keep their names, origins, axes, limits, damping, friction and effort and velocity
limits, fixed joints are kept as fixed joints; <mimic> becomes a coupling; the root link is welded to the world; gravity (0, 0, -9.81)
m/s^2 unless --gravity), or a plugin model expanded. The file loads back to the same
equations. It is written atomically: a failure leaves no partial file. An existing OUT.json is
replaced only with --force, and never when it is MODEL itself.
)";

}  // namespace

int cmd_import(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "force"}, {"output", "gravity"});
  if (a.has("help")) {
    std::cout << kImportHelp;
    return 0;
  }
  if (a.positional.size() != 1) throw CliError("expected one MODEL file (try --help)");
  if (!a.has("output")) throw CliError("-o OUT.json is required (try --help)");
  const std::string& out = a.options.at("output");
  std::error_code ec;
  if (const std::string input = input_at(out, model_inputs(a.positional[0])); !input.empty())
    throw CliError("-o " + out + " is " + input);
  if (std::filesystem::exists(out, ec) && !a.has("force"))
    throw CliError(out + ": exists (use --force to replace it)");
  const LoadOptions opt = load_options(a);
  Json doc = model_document(a.positional[0], opt);
  if (opt.gravity) doc["gravity"] = {opt.gravity->x(), opt.gravity->y(), opt.gravity->z()};
  std::string singular;  // the model must compile before anything is written
  (void)load_description(a, singular);
  if (!singular.empty()) std::cerr << "femdyn import: note: " << safe_message(singular) << "\n";
  try {
    write_file_atomic(out, readable_json(doc), a.has("force"));
  } catch (const std::runtime_error& e) {
    throw CliError(e.what());
  }
  std::cerr << "femdyn import: wrote " << escaped(out) << "\n";
  return 0;
}

}  // namespace femdyn::cli
