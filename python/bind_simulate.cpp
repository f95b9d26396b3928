// femdyn.simulate: the motion from (q0, q̇0) under a constant τ by an integrator of
// sim/integrator.hpp, as `femdyn simulate` runs it (cli/simulate.cpp), into arrays.
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/actuation_table.hpp"
#include "python/py_model.hpp"
#include "python/run_stats.hpp"
#include "sim/run_report.hpp"
#include "sim/simulation_request.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

// Python's spelling of the request's options (sim/simulation_request.hpp): the argument names.
const Door kPython{[](std::string_view name) { return std::string(name); },
                   [](double bytes) { return set_max_memory_text(bytes); }};

// Rows recorded during the run (the GIL released), turned into arrays after it.
struct RunRows {
  std::vector<double> t, y, kinetic, potential, work;
  void add(double time, const VecX& state, const Energy& e, double w) {
    t.push_back(time);
    y.insert(y.end(), state.data(), state.data() + state.size() - 1);  // q, q̇ (not W)
    kinetic.push_back(e.kinetic);
    potential.push_back(e.potential);
    work.push_back(w);
  }
};

// τ(t) from samples (t_r, τ_r) as `femdyn simulate --tau-csv` reads them (io/actuation_table):
//   τ(t) = τ_r + (t − t_r)/(t_{r+1} − t_r) (τ_{r+1} − τ_r) for t_r ≤ t < t_{r+1}, held outside.
// The request checks that it covers [0, t_end] and drives no undriven coordinate.
void tau_table(const Model& m, const Array& times, const Array& values, SimulationRequest& r) {
  const py::ssize_t rows = times.ndim() == 1 ? times.shape(0) : -1;
  if (rows < 2)
    throw py::value_error("tau_t: expected shape (m,) with m >= 2, got " + shape_text(times));
  if (values.ndim() != 2 || values.shape(0) != rows || values.shape(1) != m.n())
    throw py::value_error("tau: expected shape (" + std::to_string(rows) + ", " +
                          std::to_string(m.n()) + ") with tau_t, got " + shape_text(values));
  std::vector<double> t(times.data(), times.data() + rows);
  for (py::ssize_t i = 0; i < rows; ++i) {
    if (std::isfinite(t[i]) && std::abs(t[i]) > kMaxMagnitude)  // as --tau-csv's t column
      throw py::value_error("tau_t: entry " + std::to_string(i) + " " + out_of_range_text(t[i]));
    if (!std::isfinite(t[i]) || (i > 0 && !(t[i] > t[i - 1])))
      throw py::value_error("tau_t: expected finite, strictly increasing times; entry " +
                            std::to_string(i) + " is not");
  }
  r.tau_span = {t.front(), t.back()};
  // Row i is τ at t[i]: finite and bounded, as --tau-csv's rows are.
  MatX tau = batch_arg(values, "tau", m, rows, Entries::Bounded).transpose();  // n x samples
  auto table = std::make_shared<const ActuationTable>(std::move(t), std::move(tau), "tau_t");
  r.tau_option = "tau_t";
  r.tau_largest = table->largest();
  r.tau = [table](double time, VecX& out) { (*table)(time, out); };
}

py::array_t<double> vector_array(const std::vector<double>& x) {
  py::array_t<double> a = new_array({static_cast<py::ssize_t>(x.size())});
  std::copy(x.begin(), x.end(), a.mutable_data());
  return a;
}

// The arguments as a request (sim/simulation_request.hpp), checked as `femdyn simulate` checks its
// options; the rows are held in memory (6n + 13 numbers a row, recorded then copied).
SimulationRequest request_of(const Model& m, double t_end, const OptArray& q0_in,
                             const OptArray& qd0_in, const std::string& integrator,
                             std::optional<double> dt, std::optional<double> rtol,
                             std::optional<double> atol, const OptArray& tau_in,
                             const OptArray& tau_t_in, const OptArray& t_eval_in,
                             std::optional<long> every, std::optional<double> max_steps,
                             std::optional<double> baumgarte, std::optional<double> max_order) {
  SimulationRequest r;
  r.t_end = t_end;
  r.options = integrator_options(
      {text_arg(integrator, "integrator"), dt, rtol, atol, std::nullopt, max_steps, max_order},
      kPython);
  r.q0 = configuration_arg(q0_in, "q0", m);
  r.qd0 = vector_arg(qd0_in, "qd0", m);
  r.baumgarte = baumgarte;
  if (every) r.every = static_cast<double>(*every);
  if (t_eval_in) {
    const Array& te = *t_eval_in;
    if (te.ndim() != 1) throw py::value_error("t_eval: expected shape (m,), got " + shape_text(te));
    r.times.emplace(te.data(), te.data() + te.shape(0));
  }
  r.bytes_per_row = dense_bytes(6.0 * m.n() + 13, 1);
  if (tau_t_in) {
    if (!tau_in) throw py::value_error("tau_t: needs tau, shape (m, n)");
    tau_table(m, *tau_t_in, *tau_in, r);
  } else {
    const VecX u = vector_arg(tau_in, "tau", m, Entries::Bounded);
    r.tau_largest = u.cwiseAbs();
    if (!u.isZero(0)) r.tau = [u](double, VecX& out) { out = u; };
  }
  return r;
}

py::dict simulate(const PyModel& self, double t_end, const OptArray& q0_in, const OptArray& qd0_in,
                  const std::string& integrator, std::optional<double> dt,
                  std::optional<double> rtol, std::optional<double> atol, const OptArray& tau_in,
                  const OptArray& tau_t_in, const OptArray& t_eval_in, std::optional<long> every,
                  bool check, std::optional<double> max_steps, std::optional<double> baumgarte,
                  std::optional<double> max_order) {
  const Model& m = *self.model;
  SimulationRequest request;
  StateAssembly loops;
  try {
    request = request_of(m, t_end, q0_in, qd0_in, integrator, dt, rtol, atol, tau_in, tau_t_in,
                         t_eval_in, every, max_steps, baumgarte, max_order);
    loops = check_request(m, request, kPython);
  } catch (const RequestError& e) {
    throw py::value_error(e.what());
  } catch (const MemoryRefused& e) {
    throw MemoryRefused(std::string("simulate: ") + e.what());
  }
  RunRows rows;
  SimulationReport report;
  {
    py::gil_scoped_release release;
    // Ctrl-C reaches the run, inside its steps too: Python's signal check every 20 ms of wall
    // time (the GIL taken briefly).
    auto next_look = std::chrono::steady_clock::now();
    report = run_simulation(
        m, request, loops,
        [&rows](const Integrator& i, const Energy& E) { rows.add(i.t(), i.state(), E, i.work()); },
        [&next_look](double) {
          const auto now = std::chrono::steady_clock::now();
          if (now < next_look) return false;
          next_look = now + std::chrono::milliseconds(20);
          py::gil_scoped_acquire acquire;
          return PyErr_CheckSignals() != 0;
        });
    if (report.run.interrupted) {
      py::gil_scoped_acquire acquire;
      throw py::error_already_set();
    }
  }
  const Status& st = report.run.status;
  if (report.run.refused) throw py::value_error(st.message);  // before any work: the arguments'
  if (!st.ok && check) throw NumericalError(st.message);

  const py::ssize_t k = static_cast<py::ssize_t>(rows.t.size()), n = m.n(), nq = m.n_q();
  py::array_t<double> q = new_array({k, nq}), qd = new_array({k, n});
  for (py::ssize_t i = 0; i < k; ++i) {
    const double* y = rows.y.data() + i * (nq + n);
    std::copy(y, y + nq, q.mutable_data(i, 0));
    std::copy(y + nq, y + nq + n, qd.mutable_data(i, 0));
  }
  std::vector<double> total(rows.kinetic.size());
  for (std::size_t i = 0; i < total.size(); ++i) total[i] = rows.kinetic[i] + rows.potential[i];
  py::dict d;
  d["t"] = vector_array(rows.t);
  d["q"] = q;
  d["qd"] = qd;
  d["kinetic"] = vector_array(rows.kinetic);
  d["potential"] = vector_array(rows.potential);
  d["total"] = vector_array(total);
  d["work"] = vector_array(rows.work);
  d["stats"] = json_to_python(simulation_json(m, request, report));
  return d;
}

}  // namespace

void bind_simulate(py::module_& m) {
  m.def(
      "simulate", &simulate, py::arg("model"), py::arg("t_end"), py::arg("q0") = py::none(),
      py::arg("qd0") = py::none(), py::arg("integrator") = "dopri", py::arg("dt") = py::none(),
      py::arg("rtol") = py::none(), py::arg("atol") = py::none(), py::arg("tau") = py::none(),
      py::arg("tau_t") = py::none(), py::arg("t_eval") = py::none(), py::arg("every") = py::none(),
      py::arg("check") = true, py::arg("max_steps") = py::none(), py::arg("baumgarte") = py::none(),
      py::arg("max_order") = py::none(),
      "Integrates M^s q̈ + h = Q over [0, t_end] from (q0, qd0) under tau: constant (n,), or "
      "sampled, tau (m, n) at the times tau_t (m,) covering [0, t_end], interpolated "
      "linearly as --tau-csv; by rk4, "
      "euler (dt) or dopri, bdf (rtol, atol; bdf's largest order max_order, 1 to 5, default 5: "
      "2 for undamped fast oscillation, as --max-order). Rows every `every` steps (first and last "
      "always), or at the times t_eval. Returns a dict: t, q, qd, kinetic, potential, total, "
      "work, stats. A numerical failure raises NumericalError, or with check=False returns the "
      "rows up to the last good step with stats['ok'] False (a solution that diverges is "
      "such a failure, stats['diverged'] True). A fixed-step run of more than max_steps "
      "steps (default 1e7) is refused before it starts with ValueError. A model with closed loops "
      "starts assembled onto them and moves with Baumgarte's stabilisation at `baumgarte` 1/s "
      "(default 20; 0: off), as `femdyn simulate --baumgarte`. stats has the fields "
      "`femdyn simulate --json` prints. The GIL is released.");
}

}  // namespace femdyn::python
