// femdyn._femdyn: the compiled part of the Python package femdyn (python/femdyn/__init__.py
// re-exports it). docs/python.md describes the interface.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <new>
#include <optional>
#include <stdexcept>

#include "core/model/errors.hpp"
#include "core/model/message.hpp"
#include "core/workspace/memory.hpp"
#include "python/py_model.hpp"

namespace {

namespace py = pybind11;

// The Python exception now set, with its message replaced by `what` made safe.
void reset_message(const char* what) {
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  PyErr_Fetch(&type, &value, &trace);
  Py_XDECREF(value);
  Py_XDECREF(trace);
  PyErr_SetString(type, femdyn::safe_message(what).c_str());
  Py_XDECREF(type);
}

void raise(PyObject* type, const char* what) {
  PyErr_SetString(type, femdyn::safe_message(what).c_str());
}

// The last line of defence, as the command line's main() is: every C++ exception that reaches
// Python gets a message made safe (core/model/message.hpp), with the Python type pybind11 would
// give it. femdyn's own errors are safe already (femdyn::Error); ModelError and NumericalError have
// their own translators, registered after this one and so tried first.
void translate(std::exception_ptr p) {
  try {
    std::rethrow_exception(p);
  } catch (const py::error_already_set&) {
    throw;                                    // a Python exception already: pybind11 restores it
  } catch (const py::builtin_exception& e) {  // py::value_error, type_error, …
    e.set_error();
    reset_message(e.what());
  } catch (const femdyn::MemoryRefused& e) {  // refused up front: a ValueError, as validate's
    raise(PyExc_ValueError, e.what());
  } catch (const std::bad_alloc&) {  // no estimate foresaw it: femdyn's one line
    raise(PyExc_MemoryError, ("femdyn: " + femdyn::out_of_memory_text("computing")).c_str());
  } catch (const std::out_of_range& e) {
    raise(PyExc_IndexError, e.what());
  } catch (const std::overflow_error& e) {
    raise(PyExc_OverflowError, e.what());
  } catch (const std::invalid_argument& e) {
    raise(PyExc_ValueError, e.what());
  } catch (const std::domain_error& e) {
    raise(PyExc_ValueError, e.what());
  } catch (const std::length_error& e) {
    raise(PyExc_ValueError, e.what());
  } catch (const std::range_error& e) {
    raise(PyExc_ValueError, e.what());
  } catch (const std::exception& e) {
    raise(PyExc_RuntimeError, e.what());
  }
}

}  // namespace

PYBIND11_MODULE(_femdyn, m) {
  using namespace femdyn::python;
  m.doc() = "femdyn: equations of motion of mechanisms by the equivalent-element method";
  // A bad model file (any problem femdyn reports with a location) is femdyn.ModelError, a
  // ValueError; a numerical failure at a state is femdyn.NumericalError, an ArithmeticError.
  // Bad arguments are ValueError (shapes, NaN) or TypeError (types), as pybind11 raises them.
  // Every message is one printable line (translate above).
  py::register_exception_translator(&translate);
  py::register_exception<femdyn::ModelError>(m, "ModelError", PyExc_ValueError);
  py::register_exception<NumericalError>(m, "NumericalError", PyExc_ArithmeticError);
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
  bind_loops(m);
  bind_derivatives(m);
#ifdef FEMDYN_WITH_VIEW
  bind_view(m);
#endif
  bind_batch(m);
  bind_simulate(m);
  bind_simulator(m);
  bind_validate(m);
  bind_builder(m);
  bind_statics(m);
}
