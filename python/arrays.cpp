#include "python/arrays.hpp"

#include <cmath>

namespace femdyn::python {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

namespace {

// The first non-finite entry of `data` (n per row) named, or nothing.
void check_finite(const double* data, Eigen::Index rows, const char* name, const Model& model,
                  bool batch) {
  const Eigen::Index n = model.n();
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index a = 0; a < n; ++a)
      if (!std::isfinite(data[i * n + a]))
        throw py::value_error(
            std::string(name) + ": " + (batch ? "row " + std::to_string(i) + ", " : std::string()) +
            "entry " + std::to_string(a) + " ('" + model.coordinate_names[a] + "') is NaN or Inf");
}

}  // namespace

VecX vector_arg(const Array& a, const char* name, const Model& model) {
  const Eigen::Index n = model.n();
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) +
                          ",), got " + shape_text(a));
  check_finite(a.data(), 1, name, model, false);
  return Eigen::Map<const VecX>(a.data(), n);
}

VecX vector_arg(const std::optional<Array>& a, const char* name, const Model& model) {
  return a ? vector_arg(*a, name, model) : VecX::Zero(model.n());
}

Eigen::Map<const RowMatX> batch_arg(const Array& a, const char* name, const Model& model,
                                    Eigen::Index k) {
  const Eigen::Index n = model.n();
  if (a.ndim() != 2 || a.shape(1) != n || (k >= 0 && a.shape(0) != k))
    throw py::value_error(std::string(name) + ": expected shape (" +
                          (k >= 0 ? std::to_string(k) : std::string("k")) + ", " +
                          std::to_string(n) + "), got " + shape_text(a));
  check_finite(a.data(), a.shape(0), name, model, true);
  return {a.data(), a.shape(0), n};
}

py::array_t<double> new_array(std::initializer_list<py::ssize_t> shape) {
  return py::array_t<double>(std::vector<py::ssize_t>(shape));
}

}  // namespace femdyn::python
