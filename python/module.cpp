// femdyn._femdyn: the compiled part of the Python package femdyn (python/femdyn/__init__.py
// re-exports it). docs/python.md describes the interface.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <new>
#include <optional>

#include "core/errors.hpp"
#include "core/memory.hpp"
#include "python/py_model.hpp"

PYBIND11_MODULE(_femdyn, m) {
  namespace py = pybind11;
  using namespace femdyn::python;
  m.doc() = "femdyn: equations of motion of mechanisms by the equivalent-element method";
  // A bad model file (any problem femdyn reports with a location) is femdyn.ModelError, a
  // ValueError; a numerical failure at a state is femdyn.NumericalError, an ArithmeticError.
  // Bad arguments are ValueError (shapes, NaN) or TypeError (types), as pybind11 raises them.
  py::register_exception<femdyn::ModelError>(m, "ModelError", PyExc_ValueError);
  py::register_exception<NumericalError>(m, "NumericalError", PyExc_ArithmeticError);
  // Work refused up front by the memory limit (core/memory.hpp) is a ValueError, as validate's
  // refusal; a std::bad_alloc no estimate foresaw is a MemoryError with femdyn's one line.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const femdyn::MemoryRefused& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError,
                      ("femdyn: " + femdyn::out_of_memory_text("computing")).c_str());
    }
  });
  m.def(
      "set_max_memory",
      [](std::optional<double> gb) {
        if (gb && !(*gb > 0 && *gb < 1e9))
          throw py::value_error("max_memory: expected a positive number of GB");
        femdyn::set_default_memory_limit(gb ? *gb * 1e9 : 0);
      },
      py::arg("gb"),
      "The memory limit (GB) of every call that estimates its memory first (equations, the "
      "batches, simulate, validate without max_memory=); None: half the available memory.");
  bind_model(m);
  bind_batch(m);
  bind_simulate(m);
  bind_validate(m);
  bind_builder(m);
}
