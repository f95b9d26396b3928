// femdyn._femdyn: the compiled part of the Python package femdyn (python/femdyn/__init__.py
// re-exports it). docs/python.md describes the interface.
#include <pybind11/pybind11.h>

#include "core/errors.hpp"
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
  bind_model(m);
  bind_batch(m);
  bind_simulate(m);
  bind_validate(m);
  bind_builder(m);
}
