// Batch forms: k states in (k, n) arrays, evaluated on several threads with the GIL released.
// Row i of every result is bit-for-bit what the single-state call gives for row i.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>

#include "core/equations.hpp"
#include "core/memory.hpp"
#include "core/sampling.hpp"
#include "python/parallel.hpp"
#include "python/py_model.hpp"
#include "sim/integrator.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

// The k states of a batch, row i of each a state: q sets k; q̇ and the third argument (τ or
// q̈) default to zero rows. The arrays are read in place (numpy's memory). Every entry is bounded
// as a physical input (|x| ≤ 1e100, arrays.hpp).
// With a spherical or free joint, q's rows have n_q entries and are a checked, normalised copy
// (python/arrays.hpp, configuration_batch_arg).
struct Batch {
  Eigen::Index k = 0, n = 0, nq = 0;
  const double *q = nullptr, *qd = nullptr, *third = nullptr;
  VecX zeros;          // one zero row for an absent argument
  RowMatX q_manifold;  // the normalised configurations of a non-flat model
  Batch(const Model& m, const Array& q_in, const OptArray& qd_in, const OptArray& third_in,
        const char* third_name, Entries third_entries)
      : n(m.n()), nq(m.n_q()), zeros(VecX::Zero(m.n())) {
    if (flat_model(m)) {
      q = batch_arg(q_in, "q", m, -1).data();
    } else {
      q_manifold = configuration_batch_arg(q_in, "q", m);
      q = q_manifold.data();
    }
    k = q_in.shape(0);
    if (qd_in) qd = batch_arg(*qd_in, "qd", m, k).data();
    if (third_in) third = batch_arg(*third_in, third_name, m, k, third_entries).data();
  }
  Eigen::Map<const VecX> row(const double* x, Eigen::Index i) const {
    return {x ? x + i * n : zeros.data(), n};
  }
  Eigen::Map<const VecX> configuration(Eigen::Index i) const { return {q + i * nq, nq}; }
};

// One row's buffers (the core takes VecX).
struct RowState {
  VecX q, qd, x;
  void load(const Batch& b, Eigen::Index i) {
    q = b.configuration(i);
    qd = b.row(b.qd, i);
    x = b.row(b.third, i);
  }
};

// Refuses a batch whose results (`per_row` bytes a row) and per-thread workspaces
// (`per_thread`) exceed the memory limit (core/memory.hpp), before they are allocated.
void require_batch_memory(const char* what, const Model& m, Eigen::Index k, int threads,
                          double per_row, double per_thread) {
  const double bytes = static_cast<double>(k) * per_row + threads * per_thread;
  const double rows = std::max(1.0, std::floor((memory_limit() - threads * per_thread) / per_row));
  require_memory(std::string(what) + " of " + std::to_string(k) +
                     " states of n = " + std::to_string(m.n()) + " coordinates on " +
                     std::to_string(threads) + " threads",
                 bytes, 0,
                 "split the batch into parts of at most " + format_number(rows, "%.0f") +
                     " rows, or use fewer threads, or " + set_max_memory_text(bytes));
}

py::dict equations_batch(const PyModel& self, const Array& q, const OptArray& qd,
                         const OptArray& tau, int threads) {
  const Model& m = *self.model;
  const Batch b(m, q, qd, tau, "tau", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  require_batch_memory("equations_batch", m, k, batch_threads(k, threads),
                       dense_bytes(n + 3, n) + 64, evaluation_bytes(m));
  py::array_t<double> M = new_array({k, n, n}), h = new_array({k, n}), Q = new_array({k, n}),
                      qdd = new_array({k, n});
  py::array_t<bool> ok(std::vector<py::ssize_t>{k});
  double *pM = M.mutable_data(), *ph = h.mutable_data(), *pQ = Q.mutable_data(),
         *pqdd = qdd.mutable_data();
  bool* pok = ok.mutable_data();
  std::vector<std::string> failures(k);
  const int nthreads = batch_threads(k, threads);
  {
    py::gil_scoped_release release;
    for_each_row(m, k, nthreads, [&](Workspace& ws, Eigen::Index i) {
      thread_local RowState s;
      s.load(b, i);
      Status st;
      try {
        equations_at(m, ws, s.q, s.qd, s.x, st);
      } catch (const NumericalError& e) {
        throw NumericalError("row " + std::to_string(i) + ": " + e.what());
      }
      Eigen::Map<RowMatX>(pM + i * n * n, n, n) = ws.Ms;
      Eigen::Map<VecX>(ph + i * n, n) = ws.h;
      Eigen::Map<VecX>(pQ + i * n, n) = ws.Q;
      if (st.ok)
        Eigen::Map<VecX>(pqdd + i * n, n) = ws.qdd;
      else
        Eigen::Map<VecX>(pqdd + i * n, n).setConstant(std::numeric_limits<double>::quiet_NaN());
      pok[i] = st.ok;
      failures[i] = st.message;
    });
  }
  py::dict d;
  d["M"] = M;
  d["h"] = h;
  d["Q"] = Q;
  d["qdd"] = qdd;
  d["ok"] = ok;
  d["failures"] = failures;
  return d;
}

// forward (q̈ from τ) or inverse (τ from q̈) dynamics of every row into a (k, n) array.
template <bool Forward>
py::array_t<double> dynamics_batch(const PyModel& self, const Array& q, const OptArray& qd,
                                   const OptArray& third, int threads) {
  const Model& m = *self.model;
  const Batch b(m, q, qd, third, Forward ? "tau" : "qdd", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  require_batch_memory(Forward ? "forward_dynamics_batch" : "inverse_dynamics_batch", m, k,
                       batch_threads(k, threads), dense_bytes(1, n),
                       integrator_bytes(m, IntegratorKind::Rk4));  // a workspace's, at most
  py::array_t<double> out = new_array({k, n});
  double* po = out.mutable_data();
  const int nthreads = batch_threads(k, threads);
  {
    py::gil_scoped_release release;
    for_each_row(m, k, nthreads, [&](Workspace& ws, Eigen::Index i) {
      thread_local RowState s;
      s.load(b, i);
      const VecX* result = &ws.tau;
      if constexpr (Forward) {
        const Status st = forward_dynamics(m, ws, s.q, s.qd, s.x);
        if (!st.ok)
          throw NumericalError("row " + std::to_string(i) + ": at this state " + st.message);
        result = &ws.qdd;
      } else {
        inverse_dynamics(m, ws, s.q, s.qd, s.x);
      }
      for (Eigen::Index a = 0; a < n; ++a)
        if (!std::isfinite((*result)[a]))
          throw NumericalError("row " + std::to_string(i) + ": " + (Forward ? "q̈" : "τ") + " of '" +
                               m.coordinate_names[a] + "' is NaN or Inf");
      Eigen::Map<VecX>(po + i * n, n) = *result;
    });
  }
  return out;
}

}  // namespace

void bind_batch(py::module_& m) {
  py::class_<PyModel> model = py::reinterpret_borrow<py::class_<PyModel>>(m.attr("Model"));
  model
      .def("equations_batch", &equations_batch, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(), py::arg("threads") = 0,
           "equations at k states, (k, n) each: dict of M (k, n, n), h, Q, qdd (k, n; NaN rows "
           "where M^s is singular), ok (k,), failures; threads 0 = all cores; GIL released")
      .def("forward_dynamics_batch", &dynamics_batch<true>, py::arg("q"),
           py::arg("qd") = py::none(), py::arg("tau") = py::none(), py::arg("threads") = 0,
           "q̈ at k states, (k, n); NumericalError naming the first failed row")
      .def("inverse_dynamics_batch", &dynamics_batch<false>, py::arg("q"),
           py::arg("qd") = py::none(), py::arg("qdd") = py::none(), py::arg("threads") = 0,
           "τ at k states, (k, n)");
}

}  // namespace femdyn::python
