// Fuzz target: the CSV readers, on one text. As a `--tau-csv` table (io/actuation_table) for a
// two-joint model whose coordinates are named "a,b" and "pip" (a name that must be quoted),
// then as a trajectory CSV read back (io/trajectory_csv read_trajectory_csv). Expected: a
// table, or a ModelError with a printable one-line message (tests/fuzz/common.hpp). A bug
// besides crashes and other exceptions: a table whose times do not increase strictly or whose
// values are NaN, Inf or beyond 1e100; a trajectory whose header, written back field by field
// (io/csv.hpp csv_field), does not read as the same columns.
#include "io/csv.hpp"

#include <cmath>
#include <optional>

#include "compile/compile.hpp"
#include "core/model/limits.hpp"
#include "io/actuation_table.hpp"
#include "io/trajectory_csv.hpp"
#include "models/model_files.hpp"
#include "tests/fuzz/common.hpp"

using namespace femdyn;

namespace {

const Model& two_joints() {
  static const Model model = compile(parse_spec(R"({
    "name": "csv_fuzz",
    "bodies": [
      {"name": "l1", "parent": "world", "joint": {"name": "a,b", "type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]},
      {"name": "l2", "parent": "l1", "joint": {"name": "pip", "type": "revolute", "axis": [0, 0, 1],
       "origin": {"xyz": [1, 0, 0]}},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}
    ]})",
                                                "csv_fuzz.json"));
  return model;
}

void check_table(const ActuationTable& table, const Model& model) {
  VecX tau(model.n());
  double last = -INFINITY;
  for (double t : {table.t_first(), 0.5 * (table.t_first() + table.t_last()), table.t_last()}) {
    if (!(t >= last)) fuzz::bug("--tau-csv: times do not increase");
    last = t;
    table(t, tau);
    if (!tau.allFinite() || tau.cwiseAbs().maxCoeff() > kMaxMagnitude)
      fuzz::bug("--tau-csv: a value NaN, Inf or beyond the limit was accepted");
  }
}

void check_round_trip(const TrajectoryTable& table) {
  std::string header;
  for (std::size_t c = 0; c < table.columns.size(); ++c)
    header += (c ? "," : "") + csv_field(table.columns[c]);
  if (csv_fields(header, "round trip") != table.columns)
    fuzz::bug("trajectory CSV: the header written back reads as other columns");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Model& model = two_joints();
  std::optional<ActuationTable> table;
  fuzz::expected_errors_only(
      "--tau-csv", [&] { table.emplace(text, "tau.csv", model, ActuationTable::from_text); });
  if (table) check_table(*table, model);
  std::optional<TrajectoryTable> trajectory;
  fuzz::expected_errors_only("trajectory csv",
                             [&] { trajectory = read_trajectory_csv(text, "traj.csv"); });
  if (trajectory) check_round_trip(*trajectory);
  return 0;
}
