// A run's report as the Python module returns it: the JSON object `femdyn simulate --json` prints
// (io/run_report.hpp), as a dict, so that the CLI and Python give the same fields and values.
#pragma once
#include "io/params.hpp"
#include "python/arrays.hpp"

namespace femdyn::python {

// j as Python objects (dict, list, str, float, int, bool), by the json module.
py::object json_to_python(const Json& j);

}  // namespace femdyn::python
