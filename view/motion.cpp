#include "view/motion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/dynamics/equations.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "core/workspace/workspace.hpp"
#include "io/input_file.hpp"

namespace femdyn::view {
namespace {

// The column of `name`, or none.
std::optional<std::size_t> column(const TrajectoryTable& table, const std::string& name) {
  const auto it = std::find(table.columns.begin(), table.columns.end(), name);
  if (it == table.columns.end()) return std::nullopt;
  return static_cast<std::size_t>(it - table.columns.begin());
}

// The columns of `prefix` + each name; empty when some are missing and not `required`.
std::vector<std::size_t> columns(const TrajectoryTable& table, const std::string& prefix,
                                 const std::vector<std::string>& names, bool required,
                                 const std::string& source) {
  std::vector<std::size_t> out;
  for (const std::string& name : names) {
    const auto c = column(table, prefix + name);
    if (c) {
      out.push_back(*c);
      continue;
    }
    if (!required) return {};
    throw ModelError(source, "no column " + quoted_text(prefix + name) +
                                 " (a trajectory of this model has t and q_ of each coordinate)");
  }
  return out;
}

// Rows kept: all, or `limit` (≥ 2) evenly spaced with the first and the last.
std::vector<std::size_t> kept_rows(std::size_t rows, std::size_t limit) {
  std::vector<std::size_t> out;
  if (rows <= limit) {
    for (std::size_t r = 0; r < rows; ++r) out.push_back(r);
    return out;
  }
  for (std::size_t k = 0; k < limit; ++k)
    out.push_back(
        static_cast<std::size_t>(std::llround(static_cast<double>(k) * (rows - 1) / (limit - 1))));
  return out;
}

VecX entries(const std::vector<double>& row, const std::vector<std::size_t>& cols) {
  VecX v(cols.size());
  for (std::size_t i = 0; i < cols.size(); ++i) v[i] = row[cols[i]];
  return v;
}

}  // namespace

Motion posture(const Model& model, const VecX& q) {
  Workspace ws(model);
  const Energy E = energy(model, ws, q, VecX::Zero(model.n()));
  Motion m;
  m.frames.push_back({0.0, q, E.kinetic, E.potential, 0.0});
  m.energy_source = "computed";
  return m;
}

Motion trajectory(const Model& model, const TrajectoryTable& table, const std::string& source) {
  const std::size_t t_col = columns(table, "", {"t"}, true, source)[0];
  const std::vector<std::size_t> q_cols =
      columns(table, "q_", model.configuration_names, true, source);
  const std::vector<std::size_t> qd_cols =
      columns(table, "qd_", model.coordinate_names, false, source);
  const std::vector<std::size_t> energy_cols =
      columns(table, "", {"kinetic", "potential", "work"}, false, source);
  if (table.rows.empty()) throw ModelError(source, "no rows (the header alone)");

  Motion m;
  m.trajectory = true;
  m.energy_source = energy_cols.empty() ? "computed" : "trajectory";
  Workspace ws(model);
  double t_before = -INFINITY;
  m.rows = table.rows.size();
  for (const std::size_t r : kept_rows(table.rows.size(), frame_limit(model.bodies.size()))) {
    const std::vector<double>& row = table.rows[r];
    const std::string where = source + ": row " + std::to_string(r + 1);
    for (std::size_t c = 0; c < row.size(); ++c)
      if (!std::isfinite(row[c]))
        throw ModelError(where, quoted_text(table.columns[c]) + " is NaN or Inf");
    if (row[t_col] < t_before) throw ModelError(where, "t goes back in time");
    t_before = row[t_col];
    MotionFrame f{row[t_col], entries(row, q_cols)};
    if (const std::string bad = normalize_quaternions(model, f.q); !bad.empty())
      throw ModelError(where, bad);
    if (energy_cols.empty()) {
      const VecX qd = qd_cols.empty() ? VecX::Zero(model.n()) : entries(row, qd_cols);
      const Energy E = energy(model, ws, f.q, qd);
      f.kinetic = E.kinetic;
      f.potential = E.potential;
    } else {
      f.kinetic = row[energy_cols[0]];
      f.potential = row[energy_cols[1]];
      f.work = row[energy_cols[2]];
    }
    m.frames.push_back(std::move(f));
  }
  return m;
}

Motion read_trajectory(const Model& model, const std::string& path) {
  return trajectory(model, read_trajectory_csv(read_input_file(path), path), path);
}

}  // namespace femdyn::view
