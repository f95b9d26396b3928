// Model._write_view: the page of `femdyn view` from Python (view/page.hpp); femdyn/__init__.py
// wraps it as Model.view, which also shows the page inline in Jupyter (docs/view.md).
#include <pybind11/stl.h>

#include "io/atomic_file.hpp"
#include "models/model_files.hpp"
#include "python/py_model.hpp"
#include "view/page.hpp"

namespace femdyn::python {
namespace {

// The motion: a trajectory CSV file, or its text (femdyn.simulate's rows, written by
// femdyn/__init__.py), or one posture q (the neutral configuration when absent).
view::Motion motion_of(const Model& m, const std::optional<std::string>& traj_path,
                       const std::optional<std::string>& traj_text, const std::optional<Array>& q) {
  if (traj_path) return view::read_trajectory(m, *traj_path);
  if (traj_text) return view::trajectory(m, read_trajectory_csv(*traj_text, "traj"), "traj");
  return view::posture(m, configuration_arg(q, "q", m));
}

void write_view(const PyModel& self, const std::string& path, bool force,
                const std::optional<std::string>& traj_path,
                const std::optional<std::string>& traj_text, const std::optional<Array>& q) {
  const Model& m = *self.model;
  // --force replaces an older page, never an input of this view (the model's own files, the
  // trajectory), as at the CLI's door.
  std::vector<RunInput> inputs =
      self.source.empty() ? std::vector<RunInput>{} : model_inputs(self.source);
  if (traj_path) inputs.emplace_back(*traj_path, "the trajectory file (traj)");
  if (const std::string input = input_at(text_arg(path, "path"), inputs); !input.empty())
    throw py::value_error("path: " + path + " is " + input);
  const view::Motion motion = motion_of(m, text_arg(traj_path, "traj"), traj_text, q);
  py::gil_scoped_release release;
  view::write_model_page(text_arg(path, "path"), m, self.source, motion, force);
}

}  // namespace

void bind_view(py::module_& m) {
  auto cls = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  cls.def("_write_view", &write_view, py::arg("path"), py::arg("force"),
          py::arg("traj_path") = py::none(), py::arg("traj_text") = py::none(),
          py::arg("q") = py::none(), "the page of femdyn view (use Model.view)");
}

}  // namespace femdyn::python
