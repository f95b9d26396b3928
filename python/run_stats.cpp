#include "python/run_stats.hpp"

namespace femdyn::python {

py::object json_to_python(const Json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

}  // namespace femdyn::python
