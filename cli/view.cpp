// femdyn view: the model and its motion as one self-contained 3-D page (view/, docs/view.md).
#include <filesystem>
#include <iostream>

#include "cli/commands.hpp"
#include "core/model/names.hpp"
#include "io/atomic_file.hpp"
#include "models/model_files.hpp"
#include "view/page.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kViewHelp =
    R"(usage: femdyn view MODEL [--traj TRAJ.csv | --q …] [--out view.html] [--force]
                    [--gravity gx,gy,gz] [--floating-base]

Writes one HTML page (default view.html) that shows the model in 3-D in any browser, offline:
the bodies, each in its colour and named on hover; the joints and their axes; the body frames
and the named frames; the elements as the method sees them (lumped points as spheres sized by
mass, space bars and rods as cylinders, rotary nodes as discs, each element's nodes); a URDF
robot's visual boxes, cylinders and spheres. With --traj (a trajectory CSV of femdyn simulate)
the page plays the motion: play and pause, a time slider, the speed, loop, and beside the view
the coordinates and the energy balance against time; the URL's #t=SECONDS opens it paused at
that time. --q shows one posture (n_q values; default the neutral configuration). At most 1500
frames of a trajectory are kept (evenly spaced). Each body's pose is computed here, by femdyn's
kinematics; the page only draws. The page holds three.js (docs/view.md): about 2 MB.
The file is written atomically, and an existing one is replaced only with --force.
)";

}  // namespace

int cmd_view(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "force"}, {"traj", "q", "out", "gravity"});
  if (a.has("help")) {
    std::cout << kViewHelp;
    return 0;
  }
  if (a.has("traj") && a.has("q")) throw CliError("--traj and --q: give one of them");
  std::string singular;  // the page draws poses: M^s need not be regular
  const Model m = load_description(a, singular);
  if (!singular.empty()) std::cerr << "femdyn view: note: " << safe_message(singular) << "\n";
  const std::string out = a.has("out") ? a.options.at("out") : "view.html";
  std::error_code ec;
  std::vector<RunInput> inputs = model_inputs(a.positional[0]);
  if (a.has("traj")) inputs.emplace_back(a.options.at("traj"), "the --traj file");
  if (const std::string input = input_at(out, inputs); !input.empty())
    throw CliError("--out " + out + " is " + input);
  if (std::filesystem::exists(out, ec) && !a.has("force"))
    throw CliError(out + ": exists (use --force to replace it)");
  const view::Motion motion = a.has("traj") ? view::read_trajectory(m, a.options.at("traj"))
                                            : view::posture(m, configuration_vector(a, "q", m));
  view::write_model_page(out, m, a.positional[0], motion, a.has("force"));
  std::cerr << "femdyn view: wrote " << escaped(out) << " (" << m.bodies.size() << " bodies, "
            << m.elements.size() << " elements, " << motion.frames.size() << " frames";
  if (motion.frames.size() < motion.rows)
    std::cerr << " of the trajectory's " << motion.rows
              << " rows, evenly spaced: a page holds at most " << view::frame_limit(m.bodies.size())
              << " frames of " << m.bodies.size() << " bodies";
  std::cerr << ")\n";
  return 0;
}

}  // namespace femdyn::cli
