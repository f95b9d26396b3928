#include "io/actuation_table.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string_view>

#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/csv.hpp"
#include "io/input_file.hpp"

namespace femdyn {
namespace {

// The lines of a file's text, read in place.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
    line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return true;
  }
  // The lines after the current one (at most: some may be blank).
  std::size_t lines_left() const {
    if (pos_ >= text_.size()) return 0;
    const std::string_view rest = text_.substr(pos_);
    return static_cast<std::size_t>(std::count(rest.begin(), rest.end(), '\n')) +
           (rest.back() == '\n' ? 0 : 1);
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

}  // namespace

ActuationTable::ActuationTable(const std::string& path, const Model& m, double memory_given)
    : ActuationTable(read_input_file(path), path, m, from_text, memory_given) {}

ActuationTable::ActuationTable(const std::string& text, const std::string& path, const Model& m,
                               FromText, double memory_given)
    : path_(path), n_(m.n()) {
  // The text is read once and parsed in place; each row's numbers go straight into t_ and tau_,
  // reserved for the lines the file has: the memory is the file's size and 8 (n + 1) bytes a
  // row.
  Lines in(text);
  const int n = m.n();
  std::string_view line;
  int lineno = 1;
  if (!in.next(line)) throw ModelError(path, "empty file (expected a header t,<coordinates>)");
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
  std::vector<double> v(head.size());
  while (in.next(line)) {
    ++lineno;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    const std::string where = path + ":" + std::to_string(lineno);
    const std::vector<std::string> cells = csv_fields(line, where);
    if (cells.size() != head.size())
      throw ModelError(where, std::to_string(cells.size()) + " columns, the header has " +
                                  std::to_string(head.size()));
    if (t_.empty()) reserve_rows(1 + in.lines_left(), memory_given);
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
    if (!t_.empty() && !(v[0] > t_.back()))
      throw ModelError(where, "t must increase strictly from row to row");
    t_.push_back(v[0]);
    for (int k = 0; k < n; ++k) tau_.push_back(v[column_of[k]]);
  }
  if (t_.empty()) throw ModelError(path, "no rows after the header");
}

ActuationTable::ActuationTable(std::vector<double> t, const MatX& tau, std::string path)
    : path_(std::move(path)),
      n_(static_cast<int>(tau.rows())),
      t_(std::move(t)),
      tau_(tau.data(), tau.data() + tau.size()) {}

void ActuationTable::reserve_rows(std::size_t rows, double memory_given) {
  // At most `rows` rows (the lines left): refused beyond the memory limit.
  const double bytes = 8.0 * (n_ + 1) * static_cast<double>(rows);
  require_memory(path_ + ": a table of up to " + format_short(static_cast<double>(rows)) +
                     " rows of " + std::to_string(n_ + 1) + " numbers",
                 bytes, memory_given,
                 "use a table with fewer rows, or " + max_memory_option(bytes) +
                     " if that much memory is free");
  t_.reserve(rows);
  tau_.reserve(rows * static_cast<std::size_t>(n_));
}

VecX ActuationTable::largest() const {
  const Eigen::Map<const MatX> rows(tau_.data(), n_, static_cast<Eigen::Index>(t_.size()));
  return rows.cwiseAbs().rowwise().maxCoeff();
}

void ActuationTable::operator()(double t, VecX& tau) const {
  // τ(t) = τ_r + (t − t_r)/(t_{r+1} − t_r) (τ_{r+1} − τ_r) for t_r ≤ t < t_{r+1}; held outside.
  const auto column = [this](std::ptrdiff_t r) {
    return Eigen::Map<const VecX>(tau_.data() + r * n_, n_);
  };
  if (t <= t_.front()) {
    tau = column(0);
    return;
  }
  if (t >= t_.back()) {
    tau = column(static_cast<std::ptrdiff_t>(t_.size()) - 1);
    return;
  }
  const auto r = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin() - 1;
  const double s = (t - t_[r]) / (t_[r + 1] - t_[r]);
  tau = (1 - s) * column(r) + s * column(r + 1);
}

}  // namespace femdyn
