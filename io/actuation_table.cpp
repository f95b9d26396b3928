#include "io/actuation_table.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"
#include "core/limits.hpp"
#include "core/names.hpp"
#include "io/csv.hpp"
#include "io/input_file.hpp"

namespace femdyn {
ActuationTable::ActuationTable(const std::string& path, const Model& m)
    : ActuationTable(read_input_file(path), path, m, from_text) {}

ActuationTable::ActuationTable(const std::string& text, const std::string& path, const Model& m,
                               FromText)
    : path_(path) {
  std::istringstream in(text);
  const int n = m.n();
  std::string line;
  int lineno = 1;
  if (!std::getline(in, line))
    throw ModelError(path, "empty file (expected a header t,<coordinates>)");
  const std::vector<std::string> head = csv_fields(line, path + ":1");
  if (head.empty() || head[0] != "t")
    throw ModelError(path + ":1", "the first column must be 't' (time in s)");
  std::vector<int> column_of(n, -1);  // coordinate -> CSV column
  for (std::size_t c = 1; c < head.size(); ++c) {
    std::string name = head[c];
    auto it = std::find(m.coordinate_names.begin(), m.coordinate_names.end(), name);
    if (it == m.coordinate_names.end() && name.rfind("tau_", 0) == 0)
      it = std::find(m.coordinate_names.begin(), m.coordinate_names.end(), name.substr(4));
    if (it == m.coordinate_names.end())
      throw ModelError(path + ":1", "column " + std::to_string(c + 1) + " " + quoted_text(name) +
                                        " is not a coordinate of " + m.name);
    const auto k = it - m.coordinate_names.begin();
    if (column_of[k] >= 0)
      throw ModelError(path + ":1", "coordinate '" + *it + "' has two columns");
    column_of[k] = static_cast<int>(c);
  }
  for (int k = 0; k < n; ++k)
    if (column_of[k] < 0)
      throw ModelError(path + ":1", "no column for coordinate '" + m.coordinate_names[k] + "'");
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = path + ":" + std::to_string(lineno);
    const std::vector<std::string> cells = csv_fields(line, where);
    if (cells.size() != head.size())
      throw ModelError(where, std::to_string(cells.size()) + " columns, the header has " +
                                  std::to_string(head.size()));
    std::vector<double> v(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string column = "column " + std::to_string(c + 1);
      std::size_t used = 0;
      bool overflow = false;
      try {
        v[c] = std::stod(cells[c], &used);
      } catch (const std::out_of_range&) {
        // As the command line reads numbers (cli parse_numbers): an overflow (1e400) is out of
        // range, an underflow (1e-400) is its nearest double (0 or a subnormal).
        char* end = nullptr;
        v[c] = std::strtod(cells[c].c_str(), &end);
        used = static_cast<std::size_t>(end - cells[c].c_str());
        overflow = !(std::abs(v[c]) < 1);
      } catch (const std::exception&) {
        used = 0;
      }
      if (cells[c].empty() || used != cells[c].size())
        throw ModelError(where, column + ": " + quoted_text(cells[c]) + " is not a number");
      // t and τ are physical numbers like the model's and --tau's: finite, |x| ≤ 1e100.
      if (overflow) throw ModelError(where, column + ": " + quoted_text(cells[c]) + kOutOfRange);
      if (!std::isfinite(v[c])) throw ModelError(where, column + " is NaN or Inf");
      if (std::abs(v[c]) > kMaxMagnitude)
        throw ModelError(where, column + ": " + out_of_range_text(v[c]));
    }
    if (!rows.empty() && !(v[0] > rows.back()[0]))
      throw ModelError(where, "t must increase strictly from row to row");
    rows.push_back(std::move(v));
  }
  if (rows.empty()) throw ModelError(path, "no rows after the header");
  t_.resize(rows.size());
  tau_.resize(n, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    t_[r] = rows[r][0];
    for (int k = 0; k < n; ++k) tau_(k, static_cast<Eigen::Index>(r)) = rows[r][column_of[k]];
  }
}

void ActuationTable::operator()(double t, VecX& tau) const {
  // τ(t) = τ_r + (t − t_r)/(t_{r+1} − t_r) (τ_{r+1} − τ_r) for t_r ≤ t < t_{r+1}; held outside.
  if (t <= t_.front()) {
    tau = tau_.col(0);
    return;
  }
  if (t >= t_.back()) {
    tau = tau_.col(tau_.cols() - 1);
    return;
  }
  const auto r = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin() - 1;
  const double s = (t - t_[r]) / (t_[r + 1] - t_[r]);
  tau = (1 - s) * tau_.col(r) + s * tau_.col(r + 1);
}

}  // namespace femdyn
