// femdyn linearize: the state-space linearisation of the dynamics at a state
// (core/derivatives/derivatives.hpp),
//   d/dt (ξ, v) = A (ξ, v) + B τ,   A = ∂(ξ̇, v̇)/∂(ξ, v),   B = ∂(ξ̇, v̇)/∂τ,
// ξ the tangent coordinates q ⊕ ξ around the state's q (ξ = q − q₀ on flat joints).
#include <cmath>
#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/equations.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/output.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kLinearizeHelp =
    R"(usage: femdyn linearize MODEL [--q …] [--qd …] [--tau …] [--json] [--gravity gx,gy,gz]
                        [--baumgarte W] [--max-memory GB]

The linearisation of the equations of motion at the state (--q: n_q values, default the neutral
configuration; --qd, --tau: n values each, default 0):
  d/dt (ξ, v) = A (ξ, v) + B u,   A = ∂(ξ̇, v̇)/∂(ξ, v) (2n × 2n),   B = ∂(ξ̇, v̇)/∂u (2n × n_a),
u the τ of the actuated coordinates (all n, but a free joint's and those of a joint with
"actuated": false: τ = S u, docs/control.md#actuation),
with v̇ = q̈ and ξ the tangent coordinates around q: q + ξ on a flat joint; q ⊗ exp(ξ) on a
spherical joint, whose ξ̇ = J_r(ξ)⁻¹ ω turns A's top-left block (−½ [ω]×); (p + R ξ_p,
q ⊗ exp(ξ_r)) on a free joint (also −[v]× from ξ̇_p = exp(ξ_r) v). By analytic derivatives of
the dynamics (docs/derivatives.md): trees with linear couplings, springs, dampers, friction,
rotors, stops and loads, closed loops; other models are refused in one line.

A model with closed loops (docs/loops.md) is linearised through its constrained equations with
Baumgarte's stabilisation at --baumgarte W (1/s; default 20, the simulator's), at the state as
given (as the Python module's Model.linearize; off the loops, the stabilised equations there),
or without --q at the neutral configuration assembled onto the loops, as femdyn simulate starts
(--json gives the state used):
B's lower block is then the projected inverse M⁻¹ − Y S⁺ Yᵀ (Y = M⁻¹ Φ_qᵀ, S = Φ_q Y: no
torque moves q̈ off the loops), and at an equilibrium A has the pair −W for each direction off
the loops (at W = 0 a double zero).

--json prints {"n", "coordinates", "q", "qd", "tau", "inputs", "A", "B"}, A and B as lists of
rows, "inputs" the names of u's entries. A and its printed form grow as n²: beyond the memory
limit (--max-memory GB, default half the available memory) the command is refused before any
work, with the memory it would need.
)";

}  // namespace

int cmd_linearize(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"},
                            {"gravity", "q", "qd", "tau", "baumgarte", "max-memory"});
  if (a.has("help")) {
    std::cout << kLinearizeHelp;
    return 0;
  }
  const Model m = load(a);
  // At most: the workspace, the derivatives' buffers (twelve n × n matrices bound the five
  // results, the joint-level gains and the inverse-mass sweep), A and B, and the printed 6n²
  // numbers. Measured: n = 1500, --json, 0.78 GB against this bound's 1.75 GB.
  const double n = m.n();
  require_command_memory(a, "the linearisation of n = " + std::to_string(m.n()) + " coordinates",
                         evaluation_bytes(m) + dense_bytes(12 * n, n) + dense_bytes(6 * n, n) +
                             printed_bytes(6 * n * n + 4 * n, a.has("json")));
  const auto [q, qd, tau] = command_state(a, m);
  Workspace ws(m);
  DerivativeWorkspace d(m);  // a model it does not cover: one line, exit 1
  if (a.has("baumgarte")) {
    if (m.constraints.empty()) throw CliError("--baumgarte: the model has no constraints");
    d.baumgarte = number_option(a, "baumgarte", 0);
    if (!(d.baumgarte >= 0) || !std::isfinite(d.baumgarte))
      throw CliError("--baumgarte expects a rate >= 0 (1/s; 0: off)");
  }
  MatX A, B;
  if (const Status st = linearize_state(m, ws, d, q, qd, tau, A, B); !st.ok) {
    std::cerr << "femdyn linearize: " << escaped(a.positional[0]) << ": at this state "
              << safe_message(st.message) << "\n";
    return 1;
  }
  if (a.has("json")) {
    std::cout << readable_json(Json{{"n", m.n()},
                                    {"coordinates", m.coordinate_names},
                                    {"q", vector_json(q)},
                                    {"qd", vector_json(qd)},
                                    {"tau", vector_json(tau)},
                                    {"inputs", actuated_names(m)},
                                    {"A", matrix_json(A)},
                                    {"B", matrix_json(B)}});
    return 0;
  }
  std::ostringstream text;
  text.precision(10);
  text << "n = " << m.n() << "; state (xi, v), xi the tangent coordinates around q\n";
  text << "A = d(xi', v')/d(xi, v) (" << 2 * m.n() << " x " << 2 * m.n() << ") =\n" << A << "\n";
  text << "B = d(xi', v')/d u (" << 2 * m.n() << " x " << m.n_actuated() << ") =\n" << B << "\n";
  if (!m.fully_actuated()) {
    text << "u = tau of the actuated coordinates:";
    for (const std::string& c : actuated_names(m)) text << " " << c;
    text << "\n";
  }
  std::cout << text.str();
  return 0;
}

}  // namespace femdyn::cli
