// The Python module's model: an immutable compiled Model, shared (by shared_ptr) with batch
// threads and integrators, plus one Workspace for the single-state calls. Those keep the GIL,
// so two Python threads never use that Workspace at once; the batch calls, simulate and
// validate release the GIL and use Workspaces of their own.
#pragma once
#include <memory>

#include "core/derivatives/derivatives.hpp"
#include "core/loops/constrained_dynamics.hpp"
#include "core/workspace/memory.hpp"
#include "core/workspace/workspace.hpp"
#include "models/model_files.hpp"
#include "python/arrays.hpp"

namespace femdyn::python {

// A model's loop buffers: a LoopWorkspace with closed loops, else null.
inline std::unique_ptr<LoopWorkspace> loops_for(const Model& model) {
  return model.constraints.empty() ? nullptr : std::make_unique<LoopWorkspace>(model);
}

struct PyModel {
  explicit PyModel(Model m)
      : model(std::make_shared<const Model>(std::move(m))), ws(*model), loops(loops_for(*model)) {}
  std::shared_ptr<const Model> model;
  Workspace ws;
  std::unique_ptr<LoopWorkspace> loops;              // with closed loops: their buffers (else null)
  std::unique_ptr<DerivativeWorkspace> derivatives;  // made by the first derivatives call
  std::string source;  // the file it was loaded from (femdyn.load), else ""
  LoadOptions load;    // how it was loaded (gravity, floating base, inertia balancing)
  // What it was compiled from (the file's spec, or the Builder's): Model.statics compiles it at
  // each load factor (sim/statics.hpp).
  std::shared_ptr<const MechanismSpec> spec;
};

// M, h, Q and q̈ at one state; qdd is absent when forward dynamics failed (then `failure`
// says why), as `femdyn equations` prints null.
struct EquationsResult {
  MatX M;
  VecX h, Q;
  std::optional<VecX> qdd;
  std::string failure;
};

// The part of `femdyn equations` after parsing: the mechanism's forward dynamics (with closed
// loops the constrained q̈, `loops` their buffers), then evaluate (the same order, so the same
// numbers). Throws NumericalError if M^s, h, Q or q̈ is not finite.
void equations_at(const Model& model, Workspace& ws, LoopWorkspace* loops, const VecX& q,
                  const VecX& qd, const VecX& tau, Status& status);

// Inverse dynamics answers for the spanning tree alone: with closed loops τ is not unique (the
// loops' forces Φ_qᵀ λ share the load), so the doors that give τ refuse such a model (ModelError
// naming `what`).
void require_open_tree(const Model& model, const char* what);

// How to raise the memory limit (core/workspace/memory.hpp) from Python far enough for `bytes`:
// "femdyn.set_max_memory(4.9) if that much memory is free".
inline std::string set_max_memory_text(double bytes) {
  return "femdyn.set_max_memory(" + max_memory_gb(bytes) + ") if that much memory is free";
}

void bind_model(py::module_& m);
void bind_batch(py::module_& m);
void bind_simulate(py::module_& m);
void bind_simulator(py::module_& m);
void bind_validate(py::module_& m);
void bind_builder(py::module_& m);
void bind_statics(py::module_& m);  // Model.statics (python/bind_statics.cpp)
void bind_loops(py::module_& m);
void bind_derivatives(py::module_& m);  // after bind_model: methods of Model
void bind_view(py::module_& m);         // after bind_model; only with FEMDYN_WITH_VIEW

}  // namespace femdyn::python
