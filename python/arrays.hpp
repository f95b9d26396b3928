// numpy arguments of the Python module: shapes and values checked with messages that name the
// argument ("q: expected shape (4,), got (3,)"), then seen by Eigen without a copy.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <stdexcept>
#include <string>

#include "core/kinematics/frames.hpp"
#include "core/model/errors.hpp"
#include "core/model/model.hpp"

namespace femdyn::python {

namespace py = pybind11;

// float64, C order: anything else (lists, int arrays, strided views) is converted once by
// pybind11 on the way in; a float64 C-ordered array is used in place.
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
using RowMatX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A numerical failure at a state (a singular M^s, a q̈ that overflows, a coupling law undefined
// there; core's StateError): femdyn.NumericalError.
using NumericalError = StateError;

// "(3,)", "(5, 4)".
std::string shape_text(const py::array& a);

// What the entries of an argument may be. Bounded: a physical input (a state q, q̇, q̈, an
// actuation τ), like the model's numbers and the CLI's --q, --qd, --tau and --tau-csv: finite
// and |x| ≤ kMaxMagnitude (core/model/limits.hpp), one limit everywhere. Finite: any finite number.
enum class Entries { Finite, Bounded };

// A state vector: shape (n,), every entry bounded (or finite if asked). Absent (None, where
// allowed) is zero.
VecX vector_arg(const Array& a, const char* name, const Model& model,
                Entries entries = Entries::Bounded);
VecX vector_arg(const std::optional<Array>& a, const char* name, const Model& model,
                Entries entries = Entries::Bounded);
// A configuration q: shape (n_q,), finite and bounded, each quaternion of norm 1 within 1e-6
// (then normalised); the neutral configuration when absent.
VecX configuration_arg(const Array& a, const char* name, const Model& model);
VecX configuration_arg(const std::optional<Array>& a, const char* name, const Model& model);

// A batch of states: shape (k, n) with bounded (finite) entries, seen in place (row i = state
// i). `k` is the number of rows required, or -1 for the first batch argument (which sets k).
Eigen::Map<const RowMatX> batch_arg(const Array& a, const char* name, const Model& model,
                                    Eigen::Index k, Entries entries = Entries::Bounded);

// A batch of configurations of a model with a spherical or free joint: shape (k, n_q), each row
// checked as configuration_arg checks q (the message names the row), copied with its
// quaternions normalised.
RowMatX configuration_batch_arg(const Array& a, const char* name, const Model& model);

// A str argument (a path, a name, a choice), refused with ValueError if it holds a NUL character,
// as Python's open() refuses it: the system, and C++ code that takes C strings, would see only
// the part before it ("a\0b.json" would open "a").
const std::string& text_arg(const std::string& s, const char* name);
// A frame by name (ValueError naming it), and a set of axes by name (core/kinematics/frames.hpp).
int frame_arg(const Model& model, const std::string& name);
FrameAxes axes_arg(const std::string& text);
const std::optional<std::string>& text_arg(const std::optional<std::string>& s, const char* name);

// A fresh C-ordered float64 array of the given shape.
py::array_t<double> new_array(std::initializer_list<py::ssize_t> shape);

}  // namespace femdyn::python
