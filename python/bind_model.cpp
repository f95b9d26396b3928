// femdyn.load and femdyn.Model: the equations at one state (docs/python.md).
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "compile/compile.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/model_loader.hpp"
#include "io/output.hpp"
#include "models/model_files.hpp"
#include "python/py_model.hpp"
#include "python/run_stats.hpp"

namespace femdyn::python {
namespace {

using OptArray = std::optional<Array>;

// The first non-finite entry of x (a result), as the CLI refuses it.
void require_finite(const Model& model, const double* x, Eigen::Index size, Eigen::Index rows,
                    const char* what) {
  for (Eigen::Index i = 0; i < size; ++i)
    if (!std::isfinite(x[i]))
      throw NumericalError(
          overflow_text(std::string(what) + " of '" + model.coordinate_names[i % rows] + "'"));
}

// gravity= of load and loads: (3,), finite.
std::optional<Vec3> gravity_arg(const OptArray& gravity) {
  if (!gravity) return std::nullopt;
  if (gravity->ndim() != 1 || gravity->shape(0) != 3)
    throw py::value_error("gravity: expected shape (3,), got " + shape_text(*gravity));
  const double* g = gravity->data();
  if (!std::isfinite(g[0]) || !std::isfinite(g[1]) || !std::isfinite(g[2]))
    throw py::value_error("gravity: NaN or Inf");
  return Vec3(g[0], g[1], g[2]);
}

std::unique_ptr<PyModel> load(const std::string& path, const OptArray& gravity, bool floating_base,
                              bool balance_inertia) {
  LoadOptions options;
  options.floating_base = floating_base;
  options.balance_inertia = balance_inertia;
  std::vector<std::string> warnings;
  options.warn = [&warnings](const std::string& w) { warnings.push_back(w); };
  if ((options.gravity = gravity_arg(gravity))) options.gravity_source = "gravity";
  std::unique_ptr<PyModel> model;
  {
    py::gil_scoped_release release;
    model = std::make_unique<PyModel>(load_model(text_arg(path, "path"), options));
    model->spec = std::make_shared<const MechanismSpec>(read_spec(path, options));
  }
  model->source = path;
  model->load = options;
  model->load.warn = nullptr;  // the warnings were given once, here
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, safe_message(w).c_str(), 1) != 0)
      throw py::error_already_set();
  return model;
}

// A JSON model document given as text (femdyn.loads), named `name` in messages.
std::unique_ptr<PyModel> loads(const std::string& text, const std::string& name,
                               const OptArray& gravity) {
  const std::optional<Vec3> g = gravity_arg(gravity);
  std::unique_ptr<PyModel> model;
  {
    py::gil_scoped_release release;
    MechanismSpec spec = parse_spec(text, text_arg(name, "name"), default_catalog());
    if (g) {
      spec.gravity = *g;
      spec.gravity_where = spec.where + "gravity";
    }
    model = std::make_unique<PyModel>(compile(spec));
    model->spec = std::make_shared<const MechanismSpec>(std::move(spec));
  }
  return model;
}

EquationsResult equations(PyModel& self, const Array& q_in, const OptArray& qd_in,
                          const OptArray& tau_in) {
  const Model& m = *self.model;
  const VecX q = configuration_arg(q_in, "q", m), qd = vector_arg(qd_in, "qd", m),
             tau = vector_arg(tau_in, "tau", m, Entries::Bounded);
  // The workspace's M^s and factor, and M twice more on the way out (the result, numpy's).
  const double bytes = evaluation_bytes(m) + 2 * dense_bytes(m.n(), m.n());
  require_memory("equations of n = " + std::to_string(m.n()) + " coordinates", bytes, 0,
                 "use forward_dynamics (no n x n result), or " + set_max_memory_text(bytes));
  Status st;
  equations_at(m, self.ws, self.loops.get(), q, qd, tau, st);
  EquationsResult r{self.ws.Ms, self.ws.h, self.ws.Q, std::nullopt, st.message};
  if (st.ok) r.qdd = self.ws.qdd;
  return r;
}

VecX forward(PyModel& self, const Array& q, const OptArray& qd, const OptArray& tau) {
  const Model& m = *self.model;
  const Status st = mechanism_forward_dynamics(
      m, self.ws, self.loops.get(), configuration_arg(q, "q", m), vector_arg(qd, "qd", m),
      vector_arg(tau, "tau", m, Entries::Bounded));
  if (!st.ok) throw NumericalError("at this state " + st.message);
  require_finite(m, self.ws.qdd.data(), m.n(), m.n(), "q̈");
  return self.ws.qdd;
}

VecX inverse(PyModel& self, const Array& q, const OptArray& qd, const OptArray& qdd, bool tree) {
  const Model& m = *self.model;
  if (!tree) require_open_tree(m, "inverse_dynamics");
  inverse_dynamics(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m),
                   vector_arg(qdd, "qdd", m));
  require_finite(m, self.ws.tau.data(), m.n(), m.n(), "τ");
  return self.ws.tau;
}

// A frame's kinematics (core/kinematics/frames.hpp) as a dict of numpy arrays.
py::dict frame_of(PyModel& self, const std::string& name, const Array& q, const OptArray& qd,
                  const std::string& axes_text) {
  const Model& m = *self.model;
  const int f = frame_arg(m, name);
  const FrameAxes axes = axes_arg(axes_text);
  FrameKinematics k;
  frame_kinematics(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m), f, axes, k);
  if (!k.J.allFinite() || !k.bias.allFinite() || !k.p.allFinite())
    throw NumericalError(overflow_text("the kinematics of frame " + quoted_text(name), true));
  py::dict out;
  out["p"] = VecX(k.p);
  out["R"] = MatX(k.R);
  out["J"] = k.J;
  out["velocity"] = VecX(k.velocity);
  out["bias"] = VecX(k.bias);
  return out;
}

// The mechanism's centre of mass and centroidal momentum (core/kinematics/momentum.hpp) as a dict.
py::dict centroidal_dict(const MomentumKinematics& c) {
  py::dict out;
  out["mass"] = c.mass;
  out["com"] = VecX(c.com);
  out["Jcom"] = c.Jcom;
  out["com_velocity"] = VecX(c.com_velocity);
  out["com_bias"] = VecX(c.com_bias);
  out["inertia_com"] = MatX(c.inertia_com);
  out["momentum"] = VecX(c.momentum);
  out["A"] = c.A;
  out["bias"] = VecX(c.bias);
  return out;
}

void require_finite_momentum(const MomentumKinematics& c) {
  if (!c.A.allFinite() || !c.bias.allFinite() || !std::isfinite(c.mass))
    throw NumericalError(overflow_text("the momentum"));
}

py::dict centroidal_of(PyModel& self, const Array& q, const OptArray& qd) {
  const Model& m = *self.model;
  MomentumKinematics c;
  momentum_kinematics(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m), c);
  require_finite_momentum(c);
  return centroidal_dict(c);
}

py::dict generalized_of(PyModel& self, const std::string& name, const Array& q, const OptArray& qd,
                        const std::string& axes_text) {
  const Model& m = *self.model;
  const int f = frame_arg(m, name);
  const FrameAxes axes = axes_arg(axes_text);
  floating_base_rate(m);  // ModelError (a ValueError) unless one tree on a free joint
  propagate(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m),
            {.jacobian = true, .bias = true, .rows = false});
  FrameKinematics k;
  MomentumKinematics c;
  GeneralizedJacobian g;
  frame_kinematics(m, self.ws, f, axes, k);
  momentum_kinematics(m, self.ws, c);
  require_finite_momentum(c);
  generalized_jacobian(m, k, c, g);
  std::vector<std::string> names;
  for (const int r : g.rates) names.push_back(m.coordinate_names[r]);
  py::dict out;
  out["J"] = g.J;
  out["rates"] = names;
  out["rate_index"] = g.rates;
  out["drift"] = VecX(g.drift);
  return out;
}

// D as an (n, n, n) array, D[a, b, c] = D_abc, h_a = Σ_bc D_abc q̇_b q̇_c.
py::array_t<double> tensor(PyModel& self, const Array& q_in) {
  const Model& m = *self.model;
  const VecX q = configuration_arg(q_in, "q", m);
  const double n = m.n(), entries = std::max(n * n * n, m.n_u() * n * n);
  if (entries > kMaxTensorEntries)
    throw py::value_error("tensor: D needs " + std::to_string(static_cast<long>(entries)) +
                          " numbers for n = " + std::to_string(m.n()) + "; the limit is " +
                          std::to_string(static_cast<long>(kMaxTensorEntries)));
  const std::vector<MatX> D = third_order_tensor(m, self.ws, q);
  const py::ssize_t k = m.n();
  py::array_t<double> out = new_array({k, k, k});
  auto d = out.mutable_unchecked<3>();
  for (py::ssize_t a = 0; a < k; ++a)
    for (py::ssize_t b = 0; b < k; ++b)
      for (py::ssize_t c = 0; c < k; ++c) d(a, b, c) = D[a](b, c);
  return out;
}

py::dict energy_of(PyModel& self, const Array& q, const OptArray& qd) {
  const Model& m = *self.model;
  const Energy e = energy(m, self.ws, configuration_arg(q, "q", m), vector_arg(qd, "qd", m));
  py::dict d;
  d["kinetic"] = e.kinetic;
  d["potential"] = e.potential;
  d["total"] = e.total();
  return d;
}

// Per element: its type, body, node labels and N_m row (6 per node: x y z rx ry rz; 1-based
// transition-coordinate numbers, 0 = left out).
py::list correlation_table(const PyModel& self) {
  const Model& m = *self.model;
  py::list rows;
  for (const ElementEntry& e : m.elements) {
    py::dict d;
    d["element"] = std::string(e.element->type_name());
    d["body"] = e.body >= 0 ? m.bodies[e.body].name : std::string("world");
    d["nodes"] = e.node_labels;
    d["row"] = e.table_row;
    rows.append(d);
  }
  return rows;
}

}  // namespace

void equations_at(const Model& model, Workspace& ws, LoopWorkspace* loops, const VecX& q,
                  const VecX& qd, const VecX& tau, Status& status) {
  status = mechanism_forward_dynamics(model, ws, loops, q, qd, tau);
  evaluate(model, ws, q, qd, tau);
  const Eigen::Index n = model.n();
  require_finite(model, ws.Ms.data(), ws.Ms.size(), n, "M^s");
  require_finite(model, ws.h.data(), n, n, "h");
  require_finite(model, ws.Q.data(), n, n, "Q");
  if (status.ok) require_finite(model, ws.qdd.data(), n, n, "q̈");
}

void require_open_tree(const Model& model, const char* what) {
  if (!model.constraints.empty())
    throw ModelError(model.where, std::string(what) + ": the model has closed loops (" +
                                      std::to_string(model.constraint_rows) +
                                      " constraint equations): τ is not unique, the loops' forces "
                                      "Φ_qᵀ λ share the load (constrained_dynamics gives q̈ and λ "
                                      "from τ; inverse_dynamics(..., tree=True) the spanning "
                                      "tree's τ)");
}

void bind_model(py::module_& m) {
  py::class_<EquationsResult>(m, "Equations",
                              "M^s q̈ + h = Q at one state: M (n, n), h, Q, qdd (n,); qdd is "
                              "None when M^s is singular there or the state does not close the "
                              "model's loops (failure says why). With closed loops M, h, Q are "
                              "the spanning tree's and qdd the closed mechanism's")
      .def_readonly("M", &EquationsResult::M)
      .def_readonly("h", &EquationsResult::h)
      .def_readonly("Q", &EquationsResult::Q)
      .def_readonly("qdd", &EquationsResult::qdd)
      .def_readonly("failure", &EquationsResult::failure)
      .def("__getitem__",
           [](const EquationsResult& r, const std::string& key) -> py::object {
             if (key == "M") return py::cast(r.M);
             if (key == "h") return py::cast(r.h);
             if (key == "Q") return py::cast(r.Q);
             if (key == "qdd") return py::cast(r.qdd);
             throw py::key_error(key);
           })
      .def("keys",
           [](const EquationsResult&) {
             return std::vector<std::string>{"M", "h", "Q", "qdd"};
           })
      .def("__repr__", [](const EquationsResult& r) {
        return "<femdyn.Equations n=" + std::to_string(r.h.size()) +
               (r.qdd ? "" : " (no qdd: " + r.failure + ")") + ">";
      });

  py::class_<PyModel>(m, "Model", "A compiled mechanism (immutable); femdyn.load makes one")
      .def_property_readonly(
          "n", [](const PyModel& s) { return s.model->n(); },
          "the rates v (q̇ for joints of one coordinate): M^s is n × n")
      .def_property_readonly(
          "n_q", [](const PyModel& s) { return s.model->n_q(); },
          "the entries of q (n_q = n + one per spherical or free joint)")
      .def_property_readonly("n_u", [](const PyModel& s) { return s.model->n_u(); })
      .def_property_readonly("name", [](const PyModel& s) { return s.model->name; })
      .def_property_readonly(
          "coordinates", [](const PyModel& s) { return s.model->coordinate_names; },
          "the names of v's entries (base.vx, …, joint names)")
      .def_property_readonly(
          "actuated", [](const PyModel& s) { return s.model->actuated; },
          "the indices into v of the actuated coordinates, ascending (docs/control.md#actuation): "
          "every rate but a free joint's and those of a joint with actuated=False; "
          "linearize's B has these columns, and a run's tau is zero off them")
      .def_property_readonly(
          "routes",
          [](const PyModel& s) {
            py::dict d;
            for (const auto& [key, name] : route_report(*s.model).fields()) d[key.c_str()] = name;
            return d;
          },
          "which algorithm computes what on this model, by name: mass (M^s), force (h and tau), "
          "forward_dynamics (the tree's qdd), solver (M^s's factorisation, where qdd uses one), "
          "loops (closed loops' constrained qdd); as femdyn info and equations --json")
      .def_property_readonly(
          "configuration", [](const PyModel& s) { return s.model->configuration_names; },
          "the names of q's entries (base.x, …, base.qw, …, joint names)")
      .def(
          "neutral_configuration", [](const PyModel& s) { return neutral_posture(*s.model); },
          "q with every joint at 0 and every quaternion the identity (n_q entries)")
      .def_property_readonly("gravity", [](const PyModel& s) { return Vec3(s.model->gravity); })
      .def("equations", &equations, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(),
           "M^s, h, Q and q̈ at (q, q̇, τ) (omitted: zero), as `femdyn equations` computes them")
      .def_property_readonly(
          "frames",
          [](const PyModel& s) {
            std::vector<std::string> names;
            for (const Frame& f : s.model->frames) names.push_back(f.name);
            return names;
          },
          "the frames: every body by its name, then the model's named frames")
      .def("frame_kinematics", &frame_of, py::arg("frame"), py::arg("q"),
           py::arg("qd") = py::none(), py::arg("axes") = "local_world_aligned",
           "A frame's kinematics at (q, q̇) as a dict: p (3,), R (3, 3), J (6, n; linear rows "
           "then angular), velocity J q̇ (6,) and bias J̇ q̇ (6,), in axes 'local_world_aligned' "
           "(about the frame's origin, world axes), 'local' (the frame's axes) or 'world' "
           "(the body point at the world origin), as `femdyn kinematics` (docs/notation.md)")
      .def("centroidal", &centroidal_of, py::arg("q"), py::arg("qd") = py::none(),
           "The mechanism as a whole at (q, q̇) as a dict: mass, com (3,), Jcom (3, n), "
           "com_velocity, com_bias (c̈ at q̈ = 0), inertia_com (3, 3), momentum h_G (6,: linear, "
           "then angular about the centre of mass, world axes), A (6, n: h_G = A q̇) and bias "
           "(Ȧ q̇), as `femdyn kinematics` (docs/notation.md#momentum)")
      .def("generalized_jacobian", &generalized_of, py::arg("frame"), py::arg("q"),
           py::arg("qd") = py::none(), py::arg("axes") = "local_world_aligned",
           "Umetani–Yoshida's generalized Jacobian of a frame on a free-floating tree: dict of J "
           "(6, n − 6), rates (the names of its columns: every rate but the base's), rate_index "
           "and drift (6,): with no external force the frame moves with J v_m + drift "
           "(femdyn.ModelError on a model that is not one tree on a free joint)")
      .def("forward_dynamics", &forward, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("tau") = py::none(),
           "q̈ = (M^s)⁻¹ (Q − h); with closed loops the closed mechanism's (M^s q̈ + h = Q + "
           "Φ_qᵀ λ, Φ_q q̈ = −Φ̇_q q̇) at a state on them; NumericalError if M^s is singular or "
           "the state does not close the loops")
      .def("inverse_dynamics", &inverse, py::arg("q"), py::arg("qd") = py::none(),
           py::arg("qdd") = py::none(), py::kw_only(), py::arg("tree") = false,
           "τ such that M^s q̈ + h = Q(τ). With closed loops τ is not unique and the call is "
           "refused (femdyn.ModelError), unless tree=True asks for the spanning tree's τ, the "
           "loops cut (on the closed mechanism: τ + Φ_qᵀ λ)")
      .def(
          "mass_matrix",
          [](PyModel& s, const Array& q) {
            mass_matrix(*s.model, s.ws, configuration_arg(q, "q", *s.model));
            return MatX(s.ws.Ms);
          },
          py::arg("q"), "M^s(q), (n, n), at the configuration q (n_q)")
      .def(
          "bias",
          [](PyModel& s, const Array& q, const Array& qd) {
            evaluate_bias(*s.model, s.ws, configuration_arg(q, "q", *s.model),
                          vector_arg(qd, "qd", *s.model));
            return VecX(s.ws.h);
          },
          py::arg("q"), py::arg("qd"), "h(q, q̇) = D[q̇, q̇], (n,), at the configuration q (n_q)")
      .def("tensor", &tensor, py::arg("q"),
           "D (n, n, n) with h_a = Σ_bc D[a, b, c] q̇_b q̇_c (numpy: einsum('abc,b,c', D, qd, qd))")
      .def("energy", &energy_of, py::arg("q"), py::arg("qd") = py::none(),
           "{'kinetic', 'potential', 'total'} in J")
      .def("correlation_table", &correlation_table,
           "per element: {'element', 'body', 'nodes', 'row'} (row: N_m, 6 per node)")
      .def(
          "info", [](const PyModel& s) { return json_to_python(info_json(*s.model)); },
          "what `femdyn info --json` prints, as a dict")
      .def("__repr__", [](const PyModel& s) {
        return "<femdyn.Model '" + s.model->name + "' n=" + std::to_string(s.model->n()) + ">";
      });

  m.def("load", &load, py::arg("path"), py::arg("gravity") = py::none(),
        py::arg("floating_base") = false, py::arg("balance_inertia") = false,
        "A femdyn JSON model or a URDF file (*.urdf) as a Model; gravity (3,) overrides the "
        "model's; floating_base puts a free joint between the world and a URDF's root link (the "
        "CLI's --floating-base); balance_inertia replaces a URDF body's non-physical inertia by "
        "the nearest physical one, each change in the warnings (--balance-inertia). Raises "
        "femdyn.ModelError (a ValueError) naming the file, place "
        "and problem.");
  m.def("loads", &loads, py::arg("text"), py::arg("name") = "<text>",
        py::arg("gravity") = py::none(),
        "A femdyn JSON model given as a string (json.dumps of a dict) as a Model, as load reads a "
        "file; `name` stands for the file in messages. Raises femdyn.ModelError naming the place "
        "and problem.");
}

}  // namespace femdyn::python
