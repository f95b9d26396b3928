// femdyn.simulate: the motion from (q0, q̇0) under a constant τ by an integrator of
// sim/integrator.hpp, as `femdyn simulate` runs it (cli/simulate.cpp), into arrays.
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>

#include "core/limits.hpp"
#include "core/memory.hpp"
#include "core/names.hpp"
#include "io/actuation_table.hpp"
#include "python/py_model.hpp"
#include "python/run_stats.hpp"
#include "sim/control_loop.hpp"
#include "sim/integrator.hpp"
#include "sim/recorded_run.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

IntegratorOptions options_of(const std::string& integrator, std::optional<double> dt,
                             std::optional<double> rtol, std::optional<double> atol) {
  IntegratorOptions o;
  if (!parse_integrator(text_arg(integrator, "integrator"), o.kind))
    throw py::value_error("integrator: " + quoted_text(integrator) +
                          " is not one of rk4, euler, dopri, bdf");
  if (is_adaptive(o.kind)) {
    if (dt)
      throw py::value_error("dt sets the step of rk4 and euler; " + integrator +
                            " is adaptive: use rtol and atol");
    if (rtol) o.adaptive.rtol = *rtol;
    if (atol) o.adaptive.atol = *atol;
  } else {
    if (rtol || atol)
      throw py::value_error("rtol/atol apply to dopri and bdf; " + integrator +
                            " has a fixed step: use dt");
    if (dt) o.fixed.dt = *dt;
  }
  if (const std::string why = o.check(); !why.empty()) throw py::value_error(why);
  return o;
}

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
// The table must cover [0, t_end].
Actuation tau_table(const Model& m, const Array& times, const Array& values, double t_end) {
  const py::ssize_t rows = times.ndim() == 1 ? times.shape(0) : -1;
  if (rows < 2)
    throw py::value_error("tau_t: expected shape (m,) with m >= 2, got " + shape_text(times));
  if (values.ndim() != 2 || values.shape(0) != rows || values.shape(1) != m.n())
    throw py::value_error("tau: expected shape (" + std::to_string(rows) + ", " +
                          std::to_string(m.n()) + ") with tau_t, got " + shape_text(values));
  std::vector<double> t(times.data(), times.data() + rows);
  for (py::ssize_t r = 0; r < rows; ++r) {
    if (std::isfinite(t[r]) && std::abs(t[r]) > kMaxMagnitude)  // as --tau-csv's t column
      throw py::value_error("tau_t: entry " + std::to_string(r) + " " + out_of_range_text(t[r]));
    if (!std::isfinite(t[r]) || (r > 0 && !(t[r] > t[r - 1])))
      throw py::value_error("tau_t: expected finite, strictly increasing times; entry " +
                            std::to_string(r) + " is not");
  }
  if (t.front() > 0 || t.back() < t_end)
    throw py::value_error("tau_t: covers t in [" + std::to_string(t.front()) + ", " +
                          std::to_string(t.back()) + "] s; it must cover [0, t_end]");
  // Row r is τ at t[r]: finite and bounded, as --tau-csv's rows are.
  MatX tau = batch_arg(values, "tau", m, rows, Entries::Bounded).transpose();  // n x samples
  ActuationTable samples(std::move(t), std::move(tau), "tau_t");
  if (const std::string bad = unactuated_problem(m, samples.largest()); !bad.empty())
    throw py::value_error("tau: " + bad);
  return [table = std::move(samples)](double time, VecX& out) { table(time, out); };
}

py::array_t<double> vector_array(const std::vector<double>& x) {
  py::array_t<double> a = new_array({static_cast<py::ssize_t>(x.size())});
  std::copy(x.begin(), x.end(), a.mutable_data());
  return a;
}

py::dict simulate(const PyModel& self, double t_end, const OptArray& q0_in, const OptArray& qd0_in,
                  const std::string& integrator, std::optional<double> dt,
                  std::optional<double> rtol, std::optional<double> atol, const OptArray& tau_in,
                  const OptArray& tau_t_in, const OptArray& t_eval_in, long every, bool check,
                  std::optional<double> max_steps) {
  const Model& m = *self.model;
  if (!(t_end > 0) || t_end > 1e9) throw py::value_error("t_end: expected a time in (0, 1e9] s");
  if (every < 1) throw py::value_error("every: expected an integer >= 1");
  IntegratorOptions o = options_of(integrator, dt, rtol, atol);
  if (max_steps) {  // as the CLI's --max-steps: the fixed-step plan's limit, and adaptive's
    if (!(*max_steps >= 1 && *max_steps <= 1e15) || *max_steps != std::floor(*max_steps))
      throw py::value_error("max_steps: expected an integer in [1, 1e15]");
    o.fixed.max_steps = o.adaptive.max_steps = static_cast<long>(*max_steps);
  }
  const VecX q0 = configuration_arg(q0_in, "q0", m), qd0 = vector_arg(qd0_in, "qd0", m);
  std::vector<double> t_eval;
  if (t_eval_in) {
    const Array& te = *t_eval_in;
    if (te.ndim() != 1) throw py::value_error("t_eval: expected shape (m,), got " + shape_text(te));
    t_eval.assign(te.data(), te.data() + te.shape(0));
    for (std::size_t i = 0; i < t_eval.size(); ++i)
      if (!(t_eval[i] >= (i ? t_eval[i - 1] : 0.0)) || t_eval[i] > t_end)
        throw py::value_error("t_eval: expected nondecreasing times in [0, t_end]; entry " +
                              std::to_string(i) + " is not");
  }
  // Memory, before any is allocated: the run's matrices and the rows it returns (each recorded
  // in growing vectors, then copied into arrays: 6n + 13 numbers a row), where their number is
  // known: t_eval's times, or a fixed-step run's steps (up to max_steps) over `every`.
  double row_count = static_cast<double>(t_eval.size());
  if (!t_eval_in && !is_adaptive(o.kind))
    row_count = std::min(std::ceil(t_end / o.fixed.dt), static_cast<double>(o.fixed.max_steps)) /
                    static_cast<double>(every) +
                2;
  const double bytes = integrator_bytes(m, o.kind) + row_count * dense_bytes(6.0 * m.n() + 13, 1);
  require_memory("simulate: n = " + std::to_string(m.n()) + " coordinates with " + integrator +
                     " and " + format_short(row_count) + " rows",
                 bytes, 0,
                 std::string(t_eval_in ? "fewer t_eval times" : "a larger every=") +
                     (o.kind == IntegratorKind::Bdf ? ", or dopri (no Jacobian)" : "") + ", or " +
                     set_max_memory_text(bytes));
  // τ: constant (n,), a table (tau_t (m,), tau (m, n)), or none (passive).
  Actuation tau;
  bool driven = false;
  if (tau_t_in) {
    if (!tau_in) throw py::value_error("tau_t: needs tau, shape (m, n)");
    tau = tau_table(m, *tau_t_in, *tau_in, t_end);
    driven = true;
  } else {
    const VecX u = vector_arg(tau_in, "tau", m, Entries::Bounded);
    if (const std::string bad = unactuated_problem(m, u); !bad.empty())
      throw py::value_error("tau: " + bad);
    driven = !u.isZero(0);
    if (driven) tau = [u](double, VecX& out) { out = u; };
  }
  const bool is_conservative = conservative(m, driven);

  std::unique_ptr<Integrator> integ = make_integrator(m, o, tau);
  RunRows rows;
  RecordedRun run;
  {
    py::gil_scoped_release release;
    integ->reset(0, q0, qd0, t_end);
    // Ctrl-C reaches the run: Python's signal check every 256 steps (the GIL taken briefly).
    long step = 0;
    run = run_recorded(
        *integ, t_end, every, t_eval_in ? &t_eval : nullptr,
        [&rows](const Integrator& i, const Energy& E) { rows.add(i.t(), i.state(), E, i.work()); },
        [&step](double) {
          if (++step % 256 != 0) return false;
          py::gil_scoped_acquire acquire;
          return PyErr_CheckSignals() != 0;
        });
    if (run.interrupted) {
      py::gil_scoped_acquire acquire;
      throw py::error_already_set();
    }
  }
  const Status& st = run.status;
  if (run.refused) throw py::value_error(st.message);  // before any work: the arguments' fault
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
  const IntegratorStats& s = integ->stats();
  py::dict stats;
  stats["integrator"] = std::string(integ->name());
  stats["t_end"] = t_end;
  stats["t_reached"] = integ->t();
  stats["steps"] = s.steps;
  stats["rejected"] = s.rejected;
  stats["rhs_evals"] = s.rhs_evals;
  stats["jac_evals"] = s.jac_evals;
  stats["wall_time"] = run.wall_time;
  stats["integration_time"] = s.wall_time;
  stats["real_time_factor"] = s.wall_time > 0 ? integ->t() / s.wall_time : 0.0;
  stats["ok"] = st.ok;
  stats["diverged"] = st.diverged;
  stats["failure"] = st.message;
  put_run_stats(stats, m, run, is_conservative);
  py::dict d;
  d["t"] = vector_array(rows.t);
  d["q"] = q;
  d["qd"] = qd;
  d["kinetic"] = vector_array(rows.kinetic);
  d["potential"] = vector_array(rows.potential);
  d["total"] = vector_array(total);
  d["work"] = vector_array(rows.work);
  d["stats"] = stats;
  return d;
}

}  // namespace

void bind_simulate(py::module_& m) {
  m.def("simulate", &simulate, py::arg("model"), py::arg("t_end"), py::arg("q0") = py::none(),
        py::arg("qd0") = py::none(), py::arg("integrator") = "dopri", py::arg("dt") = py::none(),
        py::arg("rtol") = py::none(), py::arg("atol") = py::none(), py::arg("tau") = py::none(),
        py::arg("tau_t") = py::none(), py::arg("t_eval") = py::none(), py::arg("every") = 1,
        py::arg("check") = true, py::arg("max_steps") = py::none(),
        "Integrates M^s q̈ + h = Q over [0, t_end] from (q0, qd0) under tau: constant (n,), or "
        "sampled, tau (m, n) at the times tau_t (m,) covering [0, t_end], interpolated "
        "linearly as --tau-csv; by rk4, "
        "euler (dt) or dopri, bdf (rtol, atol). Rows every `every` steps (first and last "
        "always), or at the times t_eval. Returns a dict: t, q, qd, kinetic, potential, total, "
        "work, stats. A numerical failure raises NumericalError, or with check=False returns the "
        "rows up to the last good step with stats['ok'] False (a solution that diverges is "
        "such a failure, stats['diverged'] True). A fixed-step run of more than max_steps "
        "steps (default 1e7) is refused before it starts with ValueError. The GIL is released.");
}

}  // namespace femdyn::python
