// Batch forms: k states in (k, n) arrays, evaluated on several threads with the GIL released.
// Row i of every result is bit-for-bit what the single-state call gives for row i.
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <optional>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "python/derivative_rows.hpp"
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
// (`per_thread`) exceed the memory limit (core/workspace/memory.hpp), before they are allocated.
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
    for_each_row_with(
        m, k, nthreads, [&] { return loops_for(m); },
        [&](Workspace& ws, std::unique_ptr<LoopWorkspace>& loops, Eigen::Index i) {
          thread_local RowState s;
          s.load(b, i);
          Status st;
          try {
            equations_at(m, ws, loops.get(), s.q, s.qd, s.x, st);
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
  if constexpr (!Forward) require_open_tree(m, "inverse_dynamics_batch");
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
    for_each_row_with(
        m, k, nthreads, [&] { return loops_for(m); },
        [&](Workspace& ws, std::unique_ptr<LoopWorkspace>& loops, Eigen::Index i) {
          thread_local RowState s;
          s.load(b, i);
          const VecX* result = &ws.tau;
          if constexpr (Forward) {
            const Status st = mechanism_forward_dynamics(m, ws, loops.get(), s.q, s.qd, s.x);
            if (!st.ok)
              throw NumericalError("row " + std::to_string(i) + ": at this state " + st.message);
            result = &ws.qdd;
          } else {
            inverse_dynamics(m, ws, s.q, s.qd, s.x);
          }
          for (Eigen::Index a = 0; a < n; ++a)
            if (!std::isfinite((*result)[a]))
              throw NumericalError("row " + std::to_string(i) + ": " +
                                   overflow_text(std::string(Forward ? "q̈" : "τ") + " of '" +
                                                 m.coordinate_names[a] + "'"));
          Eigen::Map<VecX>(po + i * n, n) = *result;
        });
  }
  return out;
}

// Row-major (k, rows, cols) storage of a fixed-size or dynamic matrix at row i.
template <class Mat>
void store(double* base, Eigen::Index i, const Mat& x) {
  const Eigen::Index size = x.rows() * x.cols();
  Eigen::Map<RowMatX>(base + i * size, x.rows(), x.cols()) = x;
}

void require_finite_row(bool finite, Eigen::Index i, const std::string& what) {
  if (!finite) throw NumericalError("row " + std::to_string(i) + ": " + overflow_text(what));
}

// A thread's buffers for the derivatives (their workspace, at Baumgarte's rate ω for closed loops;
// A, B of the linearisation).
struct DerivativeScratch {
  DerivativeWorkspace d;
  MatX A, B;
  DerivativeScratch(const Model& m, double omega) : d(m) { d.baumgarte = omega; }
};

// Every row's state loaded into r, then row(ws, s, r, i) with a thread's buffers s, on
// `nthreads` threads with the GIL released; a NumericalError it throws names the row.
template <class Row>
void for_each_derivative_row(const Model& m, const Batch& b, int nthreads, double omega,
                             Row&& row) {
  py::gil_scoped_release release;
  for_each_row_with(
      m, b.k, nthreads, [&] { return DerivativeScratch(m, omega); },
      [&](Workspace& ws, DerivativeScratch& s, Eigen::Index i) {
        thread_local RowState r;
        r.load(b, i);
        try {
          row(ws, s, r, i);
        } catch (const NumericalError& e) {
          throw NumericalError("row " + std::to_string(i) + ": " + e.what());
        }
      });
}

// The analytic derivatives at k states (forward_derivatives_at per row, as Model.derivatives):
// qdd (k, n), dqdd_dq, dqdd_dv, Minv (k, n, n).
py::dict derivatives_batch(const PyModel& self, const Array& q, const OptArray& qd,
                           const OptArray& tau, int threads,
                           const std::optional<double>& baumgarte) {
  const Model& m = *self.model;
  const double omega = baumgarte_arg(m, baumgarte);
  const Batch b(m, q, qd, tau, "tau", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  const int nthreads = batch_threads(k, threads);
  require_batch_memory("derivatives_batch", m, k, nthreads, dense_bytes(3 * n + 1, n),
                       evaluation_bytes(m) + dense_bytes(8 * n, n));
  py::array_t<double> qdd = new_array({k, n}), dq = new_array({k, n, n}), dv = new_array({k, n, n}),
                      Minv = new_array({k, n, n});
  double *pqdd = qdd.mutable_data(), *pq = dq.mutable_data(), *pv = dv.mutable_data(),
         *pM = Minv.mutable_data();
  for_each_derivative_row(m, b, nthreads, omega,
                          [&](Workspace& ws, DerivativeScratch& s, RowState& r, Eigen::Index i) {
                            forward_derivatives_at(m, ws, s.d, r.q, r.qd, r.x);
                            store(pqdd, i, s.d.qdd);
                            store(pq, i, s.d.dqdd_dq);
                            store(pv, i, s.d.dqdd_dv);
                            store(pM, i, s.d.Minv);
                          });
  py::dict out;
  out["qdd"] = qdd;
  out["dqdd_dq"] = dq;
  out["dqdd_dv"] = dv;
  out["Minv"] = Minv;
  return out;
}

// (A (k, 2n, 2n), B (k, 2n, n_a)) at k states, as Model.linearize.
std::pair<py::array_t<double>, py::array_t<double>> linearize_batch(
    const PyModel& self, const Array& q, const OptArray& qd, const OptArray& tau, int threads,
    const std::optional<double>& baumgarte) {
  const Model& m = *self.model;
  const double omega = baumgarte_arg(m, baumgarte);
  const Batch b(m, q, qd, tau, "tau", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  const int nthreads = batch_threads(k, threads);
  const py::ssize_t n_a = m.n_actuated();
  require_batch_memory("linearize_batch", m, k, nthreads, dense_bytes(6 * n, n),
                       evaluation_bytes(m) + dense_bytes(14 * n, n));
  py::array_t<double> A = new_array({k, 2 * n, 2 * n}), B = new_array({k, 2 * n, n_a});
  double *pA = A.mutable_data(), *pB = B.mutable_data();
  for_each_derivative_row(m, b, nthreads, omega,
                          [&](Workspace& ws, DerivativeScratch& s, RowState& r, Eigen::Index i) {
                            linearize_at(m, ws, s.d, r.q, r.qd, r.x, s.A, s.B);  // (the single
                            store(pA, i, s.A);  // call's, so each row is its numbers bit for bit)
                            store(pB, i, s.B);
                          });
  return {A, B};
}

// A frame's kinematics at k states: p (k, 3), R (k, 3, 3), J (k, 6, n), velocity, bias (k, 6).
py::dict frame_kinematics_batch(const PyModel& self, const std::string& name, const Array& q,
                                const OptArray& qd, const std::string& axes_text, int threads) {
  const Model& m = *self.model;
  const int f = frame_arg(m, name);
  const FrameAxes axes = axes_arg(axes_text);
  const Batch b(m, q, qd, std::nullopt, "", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  const int nthreads = batch_threads(k, threads);
  require_batch_memory("frame_kinematics_batch", m, k, nthreads, dense_bytes(6, n + 5),
                       evaluation_bytes(m));
  py::array_t<double> p = new_array({k, 3}), R = new_array({k, 3, 3}), J = new_array({k, 6, n}),
                      vel = new_array({k, 6}), bias = new_array({k, 6});
  double *pp = p.mutable_data(), *pR = R.mutable_data(), *pJ = J.mutable_data(),
         *pv = vel.mutable_data(), *pb = bias.mutable_data();
  {
    py::gil_scoped_release release;
    for_each_row(m, k, nthreads, [&](Workspace& ws, Eigen::Index i) {
      thread_local RowState s;
      thread_local FrameKinematics fk;
      s.load(b, i);
      frame_kinematics(m, ws, s.q, s.qd, f, axes, fk);
      require_finite_row(fk.J.allFinite() && fk.bias.allFinite() && fk.p.allFinite(), i,
                         "the kinematics of frame " + quoted_text(name));
      store(pp, i, fk.p);
      store(pR, i, fk.R);
      store(pJ, i, fk.J);
      store(pv, i, fk.velocity);
      store(pb, i, fk.bias);
    });
  }
  py::dict d;
  d["p"] = p;
  d["R"] = R;
  d["J"] = J;
  d["velocity"] = vel;
  d["bias"] = bias;
  return d;
}

// The centroidal quantities at k states (core/kinematics/momentum.hpp), each with a leading k axis.
py::dict centroidal_batch(const PyModel& self, const Array& q, const OptArray& qd, int threads) {
  const Model& m = *self.model;
  const Batch b(m, q, qd, std::nullopt, "", Entries::Bounded);
  const py::ssize_t k = b.k, n = b.n;
  const int nthreads = batch_threads(k, threads);
  require_batch_memory("centroidal_batch", m, k, nthreads, dense_bytes(9, n + 6),
                       evaluation_bytes(m));
  py::array_t<double> mass = new_array({k}), com = new_array({k, 3}), Jcom = new_array({k, 3, n}),
                      cv = new_array({k, 3}), cb = new_array({k, 3}), I = new_array({k, 3, 3}),
                      h = new_array({k, 6}), A = new_array({k, 6, n}), bias = new_array({k, 6});
  double *pm = mass.mutable_data(), *pc = com.mutable_data(), *pJ = Jcom.mutable_data(),
         *pcv = cv.mutable_data(), *pcb = cb.mutable_data(), *pI = I.mutable_data(),
         *ph = h.mutable_data(), *pA = A.mutable_data(), *pb = bias.mutable_data();
  {
    py::gil_scoped_release release;
    for_each_row(m, k, nthreads, [&](Workspace& ws, Eigen::Index i) {
      thread_local RowState s;
      thread_local MomentumKinematics c;
      s.load(b, i);
      momentum_kinematics(m, ws, s.q, s.qd, c);
      require_finite_row(c.A.allFinite() && c.bias.allFinite(), i, "the momentum");
      pm[i] = c.mass;
      store(pc, i, c.com);
      store(pJ, i, c.Jcom);
      store(pcv, i, c.com_velocity);
      store(pcb, i, c.com_bias);
      store(pI, i, c.inertia_com);
      store(ph, i, c.momentum);
      store(pA, i, c.A);
      store(pb, i, c.bias);
    });
  }
  py::dict d;
  d["mass"] = mass;
  d["com"] = com;
  d["Jcom"] = Jcom;
  d["com_velocity"] = cv;
  d["com_bias"] = cb;
  d["inertia_com"] = I;
  d["momentum"] = h;
  d["A"] = A;
  d["bias"] = bias;
  return d;
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
           "τ at k states, (k, n)")
      .def("frame_kinematics_batch", &frame_kinematics_batch, py::arg("frame"), py::arg("q"),
           py::arg("qd") = py::none(), py::arg("axes") = "local_world_aligned",
           py::arg("threads") = 0,
           "frame_kinematics at k states: dict of p (k, 3), R (k, 3, 3), J (k, 6, n), velocity "
           "and bias (k, 6)")
      .def("derivatives_batch", &derivatives_batch, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(), py::arg("threads") = 0, py::arg("baumgarte") = py::none(),
           "Model.derivatives at k states (q (k, n_q), qd, tau (k, n)) as a dict: qdd (k, n), "
           "dqdd_dq, dqdd_dv, Minv (k, n, n); each row bit-for-bit the single call (closed "
           "loops at Baumgarte's rate `baumgarte`, as there); threads 0 = all cores; GIL released")
      .def("linearize_batch", &linearize_batch, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(), py::arg("threads") = 0, py::arg("baumgarte") = py::none(),
           "Model.linearize at k states: (A (k, 2n, 2n), B (k, 2n, n)); each row bit-for-bit "
           "the single call (closed loops at Baumgarte's rate `baumgarte`, as there); threads 0 "
           "= all cores; GIL released")
      .def("centroidal_batch", &centroidal_batch, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("threads") = 0,
           "centroidal at k states: each entry with a leading axis of k (mass (k,), A (k, 6, n), "
           "…)");
}

}  // namespace femdyn::python
