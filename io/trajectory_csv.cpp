#include "io/trajectory_csv.hpp"

#include <charconv>
#include <sstream>

#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "io/csv.hpp"

namespace femdyn {
namespace {

void put(std::ostream& out, double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip form
  out.write(buf, r.ptr - buf);
}

double number(const std::string& cell, const std::string& where, std::size_t column) {
  double x = 0;
  const char* end = cell.data() + cell.size();
  const auto r = std::from_chars(cell.data(), end, x);
  if (cell.empty() || r.ec == std::errc::invalid_argument || r.ptr != end)
    throw ModelError(
        where, "column " + std::to_string(column) + ": " + quoted_text(cell) + " is not a number");
  return x;  // out of range: from_chars leaves x as it was (0); the writer never writes one
}

}  // namespace

void write_trajectory_header(std::ostream& out, const Model& m) {
  out << "t";
  for (const auto& c : m.configuration_names) out << ',' << csv_field("q_" + c);
  for (const auto& c : m.coordinate_names) out << ',' << csv_field("qd_" + c);
  out << ",kinetic,potential,total,work\n";
}

void write_trajectory_row(std::ostream& out, double t, const VecX& y, const Energy& E) {
  put(out, t);
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    if (i == y.size() - 1) {  // W goes last, after the energies
      for (double e : {E.kinetic, E.potential, E.total()}) {
        out << ',';
        put(out, e);
      }
    }
    out << ',';
    put(out, y[i]);
  }
  out << '\n';
}

TrajectoryTable read_trajectory_csv(const std::string& text, const std::string& source) {
  TrajectoryTable table;
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line)) throw ModelError(source, "empty file (expected a header)");
  table.columns = csv_fields(line, source + ":1");
  for (int lineno = 2; std::getline(in, line); ++lineno) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = source + ":" + std::to_string(lineno);
    const std::vector<std::string> cells = csv_fields(line, where);
    if (cells.size() != table.columns.size())
      throw ModelError(where, std::to_string(cells.size()) + " columns, the header has " +
                                  std::to_string(table.columns.size()));
    std::vector<double>& row = table.rows.emplace_back(cells.size());
    for (std::size_t c = 0; c < cells.size(); ++c) row[c] = number(cells[c], where, c + 1);
  }
  return table;
}

}  // namespace femdyn
