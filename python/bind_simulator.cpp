// femdyn.Simulator: a stepper with a controller in the loop (sim/control_loop.hpp). step(tau)
// holds τ over one control period dt; run(controller, t_end) calls a Python controller
// u(t, q, qd) -> tau at every period (zero-order hold) or at every evaluation of f, and records
// the run as femdyn.simulate does. The GIL is released while the integrator runs between calls.
#include <pybind11/stl.h>

#include <chrono>
#include <cmath>

#include "core/workspace/memory.hpp"
#include "python/py_model.hpp"
#include "python/run_stats.hpp"
#include "sim/control_loop.hpp"
#include "sim/run_report.hpp"
#include "sim/simulation_request.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

IntegratorOptions stepper_options(const std::string& integrator, double dt,
                                  std::optional<long> substeps, std::optional<double> rtol,
                                  std::optional<double> atol, std::optional<int> max_order) {
  IntegratorOptions o;
  if (!parse_integrator(text_arg(integrator, "integrator"), o.kind))
    throw py::value_error("integrator: " + integrator + " is not one of rk4, euler, dopri, bdf");
  if (!(dt > 0) || !std::isfinite(dt) || dt > 1e9)
    throw py::value_error("dt: expected a control period in (0, 1e9] s");
  if (is_adaptive(o.kind)) {
    if (substeps)
      throw py::value_error("substeps sets the steps of rk4 and euler in a period; " + integrator +
                            " is adaptive: use rtol and atol");
    if (rtol) o.adaptive.rtol = *rtol;
    if (atol) o.adaptive.atol = *atol;
  } else {
    if (rtol || atol)
      throw py::value_error("rtol/atol apply to dopri and bdf; " + integrator +
                            " has a fixed step: use dt and substeps");
    const long s = substeps.value_or(1);
    if (s < 1 || s > 1000000) throw py::value_error("substeps: expected an integer in [1, 1e6]");
    o.fixed.dt = dt / static_cast<double>(s);
  }
  if (max_order) {
    if (o.kind != IntegratorKind::Bdf)
      throw py::value_error("max_order applies to bdf, the one integrator of variable order");
    o.adaptive.max_order = *max_order;
  }
  if (const std::string why = o.check(); !why.empty()) throw py::value_error(why);
  return o;
}

py::array_t<double> copy_array(const VecX& x) {
  py::array_t<double> a = new_array({static_cast<py::ssize_t>(x.size())});
  std::copy(x.data(), x.data() + x.size(), a.mutable_data());
  return a;
}

// The controller's return value as τ (n entries, finite), else a one-line ValueError.
void tau_of(const py::handle& value, const Model& m, double t, VecX& tau) {
  const std::string at = "controller at t = " + format_short(t) + " s: ";
  Array a;
  try {  // (numpy's conversion: a float64 array, or anything numpy turns into one)
    a = py::cast<Array>(value);
  } catch (const std::exception&) {
    throw py::value_error(at + "expected tau, an array of shape (" + std::to_string(m.n()) +
                          ",) of numbers, got " +
                          std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  if (a.ndim() != 1 || a.shape(0) != m.n())
    throw py::value_error(at + "expected tau of shape (" + std::to_string(m.n()) + ",), got " +
                          shape_text(a));
  tau = Eigen::Map<const VecX>(a.data(), m.n());
  if (const std::string bad = tau_problem(m, tau); !bad.empty()) throw py::value_error(at + bad);
}

// Rows of a run: (t, q, q̇, τ applied from t, W, E) at every period; τ as the dynamics sees it,
// saturated at the joints' effort limits, with a driven joint's torque at the row's state
// (Motion::driven_actuation).
struct ControlRows {
  std::vector<double> t, q, qd, tau, work, total;
  void add(const ControlLoop& loop, Motion& motion, VecX tau_k, const Energy& E) {
    const Integrator& i = loop.integrator();
    if (const Model& m = motion.model(); m.has_effort_limits)
      tau_k = tau_k.cwiseMax(-m.effort_limit).cwiseMin(m.effort_limit);
    if (!motion.model().prescribed.empty()) {
      VecX driven;
      if (motion.driven_actuation(i.t(), i.y().data(), tau_k, driven).ok) tau_k = driven;
    }
    t.push_back(i.t());
    const VecX q_now = i.q(), qd_now = i.qd();
    q.insert(q.end(), q_now.data(), q_now.data() + q_now.size());
    qd.insert(qd.end(), qd_now.data(), qd_now.data() + qd_now.size());
    tau.insert(tau.end(), tau_k.data(), tau_k.data() + tau_k.size());
    work.push_back(i.work());
    total.push_back(E.total());
  }
};

// x as a (rows, cols) array; a column (cols = 0) as (rows,).
py::array_t<double> table(const std::vector<double>& x, py::ssize_t cols) {
  const py::ssize_t rows =
      cols ? static_cast<py::ssize_t>(x.size()) / cols : static_cast<py::ssize_t>(x.size());
  py::array_t<double> a = cols == 0 ? new_array({rows}) : new_array({rows, cols});
  std::copy(x.begin(), x.end(), a.mutable_data());
  return a;
}

// Ctrl-C inside a step (a long adaptive step, a Newton iteration): while it lives, the motion
// asks Python's signal check every 20 ms of wall time, the GIL taken briefly; a pending signal
// stops the step with Status::interrupted, its KeyboardInterrupt left set for the caller.
struct CtrlC : Motion::InterruptScope {
  explicit CtrlC(Motion& m)
      : Motion::InterruptScope(m, [] {
          py::gil_scoped_acquire acquire;
          return PyErr_CheckSignals() != 0;
        }) {}
};

// Closed loops' Baumgarte rate against the stepper, as femdyn.simulate asks it
// (sim/simulation_request.hpp): a ValueError where the method cannot follow it over `t_end`
// (0 at construction: the fixed step's bound alone).
void check_baumgarte_rate(const Model& m, const IntegratorOptions& o, double t_end) {
  static const Door python{[](std::string_view name) { return std::string(name); },
                           [](double bytes) { return set_max_memory_text(bytes); }};
  try {
    check_baumgarte(m, o, std::nullopt, t_end, python);
  } catch (const RequestError& e) {
    throw py::value_error(e.what());
  }
}

class Simulator {
 public:
  Simulator(const PyModel& model, const std::string& integrator, double dt,
            std::optional<long> substeps, std::optional<double> rtol, std::optional<double> atol,
            const OptArray& q0, const OptArray& qd0, std::optional<int> max_order)
      : model_(model.model),
        options_(stepper_options(integrator, dt, substeps, rtol, atol, max_order)),
        loop_(std::make_unique<ControlLoop>(
            *model_, options_,
            ControlLoopOptions{.mode = ControlMode::PerEvaluation, .period = dt})) {
    check_baumgarte_rate(*model_, options_, 0);
    reset(q0, qd0, 0);
  }

  void reset(const OptArray& q, const OptArray& qd, double t) {
    not_running("reset");
    if (!std::isfinite(t) || std::abs(t) > 1e9) throw py::value_error("t: expected |t| <= 1e9 s");
    loop_->reset(t, configuration_arg(q, "q", *model_), vector_arg(qd, "qd", *model_));
  }

  void step(const Array& tau_in) {
    not_running("step");
    const VecX tau = vector_arg(tau_in, "tau", *model_, Entries::Bounded);
    Status st;
    {
      const CtrlC hook(loop_->integrator().motion());
      py::gil_scoped_release release;
      st = loop_->step(tau);
    }
    if (st.interrupted) throw py::error_already_set();  // (KeyboardInterrupt, set by the hook)
    if (!st.ok) throw NumericalError(st.message);
  }

  py::dict state() const {
    const Integrator& i = loop_->integrator();
    py::dict d;
    d["t"] = i.t();
    d["q"] = copy_array(i.q());
    d["qd"] = copy_array(i.qd());
    d["work"] = i.work();
    return d;
  }

  // The controller's largest output of a run.
  struct Largest {
    double value = 0, t = 0;
    Eigen::Index i = -1;
  };
  struct Unset {  // the Python controller leaves the loop with the run, whatever happens
    ControlLoop& loop;
    ~Unset() { loop.set_controller({}); }
  };
  struct Running {  // while the run lasts, whatever ends it: reset, step and run refuse
    bool& flag;
    explicit Running(bool& f) : flag(f) { flag = true; }
    ~Running() { flag = false; }
  };

  // Run's arguments checked, and its memory before any is allocated: a row a period,
  // n_q + 3n + 2 numbers, held in growing vectors and then copied into arrays (twice that at the
  // end). Whether the mode holds τ over a period.
  bool check_run(const py::object& controller, double t_end, const std::string& mode) {
    const bool hold = text_arg(mode, "mode") == "hold";
    if (!hold && mode != "evaluation")
      throw py::value_error(
          "mode: expected 'hold' (zero-order hold, one call a period) or "
          "'evaluation' (a call at every evaluation of f), got " +
          mode);
    if (!PyCallable_Check(controller.ptr()))
      throw py::type_error("controller: expected a callable controller(t, q, qd) -> tau");
    Integrator& integ = loop_->integrator();
    if (!(t_end >= integ.t()) || t_end > 1e9)
      throw py::value_error("t_end: expected a time in [t, 1e9] s, t = " + format_short(integ.t()));
    if (Status plan = integ.plan(t_end); !plan.ok) throw py::value_error(plan.message);
    check_baumgarte_rate(*model_, options_, t_end - integ.t());
    const Model& m = *model_;
    const double T = loop_->options().period;
    const double row_count = std::ceil((t_end - integ.t()) / T) + 2;
    const double bytes = 2 * row_count * dense_bytes(m.n_q() + 3.0 * m.n() + 2, 1);
    require_memory("Simulator.run: " + std::to_string(static_cast<long long>(row_count)) +
                       " rows of n = " + std::to_string(m.n()) + " coordinates",
                   bytes, 0,
                   "a shorter run (several run() calls), or " + set_max_memory_text(bytes));
    return hold;
  }

  // The rows as arrays, and the summary's fields as femdyn.simulate's (sim/run_report.hpp; a
  // controller acts), then the loop's own.
  py::dict run_result(const ControlRows& rows, RunWatch& watch, const Status& st,
                      const std::string& mode, long calls, long k_before,
                      const IntegratorStats& before,
                      std::chrono::steady_clock::time_point begin) const {
    const Integrator& integ = loop_->integrator();
    const Model& m = *model_;
    const double T = loop_->options().period;
    const IntegratorStats& s = integ.stats();
    py::dict stats = json_to_python(run_summary_json(m, watch.run(), false));
    stats["integrator"] = std::string(integ.name());
    stats["mode"] = mode;
    stats["dt"] = T;
    stats["periods"] = loop_->period_index() - k_before;
    stats["controller_calls"] = calls;
    stats["steps"] = s.steps - before.steps;
    stats["rejected"] = s.rejected - before.rejected;
    stats["rhs_evals"] = s.rhs_evals - before.rhs_evals;
    stats["integration_time"] = s.wall_time - before.wall_time;
    stats["wall_time"] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    stats["t_reached"] = integ.t();
    stats["ok"] = st.ok;
    stats["diverged"] = st.diverged;
    stats["failure"] = st.message;
    py::dict d;
    d["t"] = table(rows.t, 0);
    d["q"] = table(rows.q, m.n_q());
    d["qd"] = table(rows.qd, m.n());
    d["tau"] = table(rows.tau, m.n());
    d["work"] = table(rows.work, 0);
    d["total"] = table(rows.total, 0);
    d["stats"] = stats;
    return d;
  }

  py::dict run(const py::object& controller, double t_end, const std::string& mode, bool check) {
    not_running("run");
    const bool hold = check_run(controller, t_end, mode);
    Integrator& integ = loop_->integrator();
    const Model& m = *model_;
    const double T = loop_->options().period;
    VecX tau = VecX::Zero(m.n());
    Largest largest;  // the suspect a divergence report names
    // The controller at the current state, into tau (the GIL held).
    const auto call = [&](double t, const VecX& q, const VecX& qd, VecX& out) {
      tau_of(controller(t, copy_array(q), copy_array(qd)), m, t, out);
      Eigen::Index i = 0;
      if (out.size() && out.cwiseAbs().maxCoeff(&i) > std::abs(largest.value))
        largest = {out[i], t, i};
    };
    const Unset unset{*loop_};
    const Running running{running_};
    long calls = 0;
    if (!hold)
      loop_->set_controller([&](double t, const VecX& q, const VecX& qd, VecX& out) {
        py::gil_scoped_acquire acquire;
        ++calls;
        call(t, q, qd, out);
      });
    const double t_start = integ.t();
    const VecX q_start = integ.q(), qd_start = integ.qd();  // (a divergence's cause)
    const auto begin = std::chrono::steady_clock::now();
    const IntegratorStats before = integ.stats();
    const long k_before = loop_->period_index();
    // The run's summary, as femdyn.simulate's (python/run_stats.hpp): a row a period.
    RunWatch watch(integ);
    ControlRows rows;
    Status st;
    // Whether the controller's gain at the run's start makes the loop grow: a clause for a
    // divergence, or for a controller output driven out of range (sim/controller_diagnosis.hpp).
    const auto controller_clause = [&] {
      const Control u = [&](double t, const VecX& q, const VecX& qd, VecX& out) {
        tau_of(controller(t, copy_array(q), copy_array(qd)), m, t, out);
      };
      return loop_->controller_clause(u, t_start, q_start, qd_start, hold);
    };
    try {
      while (integ.t() < t_end - 1e-9 * T) {
        call(integ.t(), integ.q(), integ.qd(), tau);  // τ_k (in evaluation mode: the row's)
        ++calls;
        rows.add(*loop_, integ.motion(), tau, watch.at_row(integ));
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C
        {
          const CtrlC hook(integ.motion());
          py::gil_scoped_release release;
          st = hold ? loop_->step(tau) : loop_->step();
        }
        if (st.interrupted) throw py::error_already_set();
        if (!st.ok) break;
        watch.after_step(integ);
      }
    } catch (const py::value_error& e) {  // the controller's output refused
      const std::string why = controller_clause();
      if (why.empty()) throw;
      throw py::value_error(std::string(e.what()) + "; " + why);
    }
    // The end: τ the last held (ZOH's left limit).
    rows.add(*loop_, integ.motion(), tau, watch.at_row(integ));
    watch.finish(integ);
    if (!st.ok && st.diverged && largest.i >= 0) {  // the controller drove it: say how hard
      st.message += "; the controller's largest output in this run: tau of '" +
                    m.coordinate_names[largest.i] + "' = " + format_short(largest.value) +
                    " at t = " + format_short(largest.t) + " s";
      if (const std::string why = controller_clause(); !why.empty()) st.message += "; " + why;
    }
    if (!st.ok && check) throw NumericalError(st.message);
    return run_result(rows, watch, st, mode, calls, k_before, before, begin);
  }

  double t() const { return loop_->t(); }
  double dt() const { return loop_->options().period; }
  std::string integrator() const { return loop_->integrator().name(); }

 private:
  // A call from inside this Simulator's own run (its controller calling reset, step or run)
  // would move the state under the running integrator: refused, naming the call.
  void not_running(const char* what) const {
    if (running_)
      throw std::runtime_error(std::string("Simulator.") + what +
                               ": called while this Simulator's run() is in progress (from its "
                               "controller): a controller returns tau and leaves the state to "
                               "run(); call " +
                               what + " after run() returns");
  }

  std::shared_ptr<const Model> model_;
  IntegratorOptions options_;
  std::unique_ptr<ControlLoop> loop_;
  bool running_ = false;
};

}  // namespace

void bind_simulator(py::module_& m) {
  py::class_<Simulator>(
      m, "Simulator",
      "A stepper with a controller in the loop (docs/control.md): "
      "Simulator(model, integrator='rk4', dt=1e-3, substeps=None, rtol=None, "
      "atol=None, q0=None, qd0=None, max_order=None). dt is the control period; rk4 and euler "
      "take substeps steps of dt/substeps in it (default 1), dopri and bdf "
      "their own, restarted at every period where tau jumps; bdf's largest order is max_order "
      "(1 to 5, default 5; 2 for undamped fast oscillation).")
      .def(py::init<const PyModel&, const std::string&, double, std::optional<long>,
                    std::optional<double>, std::optional<double>, const OptArray&, const OptArray&,
                    std::optional<int>>(),
           py::arg("model"), py::arg("integrator") = "rk4", py::arg("dt") = 1e-3,
           py::arg("substeps") = py::none(), py::arg("rtol") = py::none(),
           py::arg("atol") = py::none(), py::arg("q0") = py::none(), py::arg("qd0") = py::none(),
           py::arg("max_order") = py::none())
      .def("step", &Simulator::step, py::arg("tau"),
           "Advances one control period dt with tau (n,) held. A numerical failure raises "
           "NumericalError (reset() before going on). The GIL is released.")
      .def("reset", &Simulator::reset, py::arg("q") = py::none(), py::arg("qd") = py::none(),
           py::arg("t") = 0.0, "Starts again at (t, q, qd) with the work W = 0.")
      .def_property_readonly("state", &Simulator::state, "dict: t, q (n_q,), qd (n,), work")
      .def_property_readonly("t", &Simulator::t)
      .def_property_readonly("dt", &Simulator::dt)
      .def_property_readonly("integrator", &Simulator::integrator)
      .def("run", &Simulator::run, py::arg("controller"), py::arg("t_end"),
           py::arg("mode") = "hold", py::arg("check") = true,
           "Runs whole periods from the current state until t >= t_end with tau = "
           "controller(t, q, qd): called at "
           "every period and held (mode='hold'), or at every evaluation of f "
           "(mode='evaluation'). Returns a dict: t (m,), q (m, n_q), qd, tau (m, n), work, total "
           "(m,), stats; tau[k] is applied from t[k] (the last row repeats the last), saturated at "
           "the "
           "joints' effort limits (stats['saturated_evaluations'] counts the evaluations that "
           "were). A wrong or "
           "NaN tau is a ValueError, the controller's own exception propagates, a numerical "
           "failure raises NumericalError (check=False: the rows so far, stats['ok'] False). "
           "One thread at a time: a Simulator is not shared between threads.");
}

}  // namespace femdyn::python
