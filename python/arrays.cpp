#include "python/arrays.hpp"

#include <cmath>

#include "core/kinematics/sampling.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"

namespace femdyn::python {

const std::string& text_arg(const std::string& s, const char* name) {
  if (const auto at = s.find('\0'); at != std::string::npos)
    throw py::value_error(std::string(name) + ": " + quoted_text(s) +
                          " contains a NUL character (at byte " + std::to_string(at) + ")");
  return s;
}

const std::optional<std::string>& text_arg(const std::optional<std::string>& s, const char* name) {
  if (s) text_arg(*s, name);
  return s;
}

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

namespace {

// The first entry of `data` (n per row) that is not finite (or, bounded, of magnitude above
// kMaxMagnitude) named with its value, or nothing.
void check_entries(const double* data, Eigen::Index rows, const char* name, const Model& model,
                   bool batch, Entries entries) {
  const Eigen::Index n = model.n();
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index a = 0; a < n; ++a) {
      const double x = data[i * n + a];
      const bool finite = std::isfinite(x);
      if (finite && (entries == Entries::Finite || std::abs(x) <= kMaxMagnitude)) continue;
      throw py::value_error(std::string(name) + ": " +
                            (batch ? "row " + std::to_string(i) + ", " : std::string()) + "entry " +
                            std::to_string(a) + " ('" + model.coordinate_names[a] + "') " +
                            (finite ? out_of_range_text(x) : std::string("is NaN or Inf")));
    }
}

// q (n_q entries): each entry bounded, each quaternion within 1e-6 of norm 1, then normalised;
// a ValueError starting with `prefix` ("q: " or "q: row 3, ") otherwise.
void check_configuration(VecX& q, const std::string& prefix, const Model& model) {
  for (Eigen::Index i = 0; i < q.size(); ++i)
    if (!std::isfinite(q[i]) || std::abs(q[i]) > kMaxMagnitude)
      throw py::value_error(prefix + "entry " + std::to_string(i) + " ('" +
                            model.configuration_names[i] + "') " +
                            (std::isfinite(q[i]) ? out_of_range_text(q[i]) : "is NaN or Inf"));
  if (const std::string bad = normalize_quaternions(model, q); !bad.empty())
    throw py::value_error(prefix + bad);
}

}  // namespace

VecX vector_arg(const Array& a, const char* name, const Model& model, Entries entries) {
  const Eigen::Index n = model.n();
  if (a.ndim() != 1 || a.shape(0) != n)
    throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(n) +
                          ",), got " + shape_text(a));
  check_entries(a.data(), 1, name, model, false, entries);
  return Eigen::Map<const VecX>(a.data(), n);
}

VecX vector_arg(const std::optional<Array>& a, const char* name, const Model& model,
                Entries entries) {
  return a ? vector_arg(*a, name, model, entries) : VecX::Zero(model.n());
}

VecX configuration_arg(const Array& a, const char* name, const Model& model) {
  if (flat_model(model)) return vector_arg(a, name, model);
  const Eigen::Index nq = model.n_q();
  if (a.ndim() != 1 || a.shape(0) != nq)
    throw py::value_error(std::string(name) + ": expected shape (" + std::to_string(nq) +
                          ",), got " + shape_text(a));
  VecX q = Eigen::Map<const VecX>(a.data(), nq);
  check_configuration(q, std::string(name) + ": ", model);
  return q;
}

VecX configuration_arg(const std::optional<Array>& a, const char* name, const Model& model) {
  return a ? configuration_arg(*a, name, model) : neutral_posture(model);
}

Eigen::Map<const RowMatX> batch_arg(const Array& a, const char* name, const Model& model,
                                    Eigen::Index k, Entries entries) {
  const Eigen::Index n = model.n();
  if (a.ndim() != 2 || a.shape(1) != n || (k >= 0 && a.shape(0) != k))
    throw py::value_error(std::string(name) + ": expected shape (" +
                          (k >= 0 ? std::to_string(k) : std::string("k")) + ", " +
                          std::to_string(n) + "), got " + shape_text(a));
  check_entries(a.data(), a.shape(0), name, model, true, entries);
  return {a.data(), a.shape(0), n};
}

RowMatX configuration_batch_arg(const Array& a, const char* name, const Model& model) {
  const Eigen::Index nq = model.n_q();
  if (a.ndim() != 2 || a.shape(1) != nq)
    throw py::value_error(std::string(name) + ": expected shape (k, " + std::to_string(nq) +
                          "), got " + shape_text(a));
  RowMatX out = Eigen::Map<const RowMatX>(a.data(), a.shape(0), nq);
  VecX q(nq);
  for (Eigen::Index i = 0; i < out.rows(); ++i) {
    q = out.row(i).transpose();
    check_configuration(q, std::string(name) + ": row " + std::to_string(i) + ", ", model);
    out.row(i) = q.transpose();
  }
  return out;
}

py::array_t<double> new_array(std::initializer_list<py::ssize_t> shape) {
  return py::array_t<double>(std::vector<py::ssize_t>(shape));
}

int frame_arg(const Model& model, const std::string& name) {
  const int f = find_frame(model, name);
  if (f < 0) throw py::value_error("no frame " + quoted_text(name) + " (model.frames names them)");
  return f;
}

FrameAxes axes_arg(const std::string& text) {
  FrameAxes axes = FrameAxes::LocalWorldAligned;
  if (!parse_frame_axes(text, axes))
    throw py::value_error("axes: expected 'local_world_aligned', 'local' or 'world', got " +
                          quoted_text(text));
  return axes;
}

}  // namespace femdyn::python
