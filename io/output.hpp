// Output formatting: the equations as text or as one JSON object, the correlation table,
// and writing files atomically (a temporary file renamed into place).
#pragma once
#include <string>
#include <vector>

#include "core/loops/constrained_dynamics.hpp"
#include "core/workspace/status.hpp"
#include "core/workspace/workspace.hpp"
#include "io/params.hpp"

namespace femdyn {

// A vector as a JSON array, a matrix as an array of its rows.
Json vector_json(const VecX& v);
Json matrix_json(const MatX& m);

// {"n", "coordinates", "q", "qd", "tau", "M", "h", "Q", "qdd"} (+ "D" when D is non-empty):
// n the number of coordinates, "coordinates" their names (as in every JSON output of femdyn).
// M, h, Q are the spanning tree's; qdd is the mechanism's (mechanism_forward_dynamics: with
// closed loops, `loops` holds λ and Φ_q and the JSON adds "lambda" and "constraint_forces"
// Φ_qᵀ λ), null when `dynamics` failed at the state (then "failure" says why).
Json equations_json(const Model& model, const Workspace& ws, const VecX& q, const VecX& qd,
                    const VecX& tau, const Status& dynamics, const LoopWorkspace* loops,
                    const std::vector<MatX>& D);

std::string equations_text(const Model& model, const Workspace& ws, const VecX& q, const VecX& qd,
                           const VecX& tau, const Status& dynamics, const LoopWorkspace* loops,
                           const std::vector<MatX>& D);

std::string info_text(const Model& model);
Json info_json(const Model& model);
// route_report's names as {"mass", "force", "forward_dynamics"[, "solver"][, "loops"]}.
Json routes_json(const Model& model);
// The actuated coordinates' names (Model::actuated), in order.
std::vector<std::string> actuated_names(const Model& model);

// The paper-style correlation table N_m: one row per element, 6 entries per node.
std::string correlation_table_text(const Model& model);

// JSON as people write it: keys in the order of the formats (a model: name, gravity, bodies, …;
// the equations: n, coordinates, q, qd, tau, M, h, Q, qdd, D), arrays of numbers (vectors, matrix
// rows) on one line, two-space indent. Numbers keep full (round-trip) precision.
std::string readable_json(const Json& doc);

// The JSON text of a --json output: nlohmann's dump (indent 2), with invalid UTF-8 written as
// U+FFFD instead of nlohmann's exception, and DEL and the C1 controls (U+0080–U+009F), which it
// leaves raw, as \u escapes: no --json output can carry a control character to a terminal
// (docs/robustness.md).
std::string json_text(const Json& doc);

// Writes content to path through an AtomicFile (io/atomic_file.hpp): readers never see a
// half-written file. Replaces an existing file.
void write_file_atomic(const std::string& path, const std::string& content, bool replace);

}  // namespace femdyn
