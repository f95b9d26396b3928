// τ(t) from a CSV file (femdyn simulate --tau-csv): a header line "t,<c1>,<c2>,…" naming every
// generalized coordinate once, each as "<name>" or "tau_<name>", in any order; then one row per
// sample time, strictly increasing. τ is interpolated linearly between rows and held at the
// last row's value after it. Fields may be quoted (RFC 4180, io/csv.hpp). Errors name the file,
// the line and the column.
#pragma once
#include <string>
#include <vector>

#include "core/model/model.hpp"

namespace femdyn {

class ActuationTable {
 public:
  // Throws ModelError ("FILE:LINE: …") on a malformed file, MemoryRefused
  // (core/workspace/memory.hpp) when its rows would need more memory than the limit (`memory_given`
  // bytes, 0: the default).
  ActuationTable(const std::string& path, const Model& model, double memory_given = 0);
  // The same from the file's text; `path` names it in errors (the CSV fuzz target).
  struct FromText {};
  static constexpr FromText from_text{};
  ActuationTable(const std::string& text, const std::string& path, const Model& model, FromText,
                 double memory_given = 0);
  // From samples already checked by the caller: t strictly increasing (at least 2), tau n × |t|
  // (column r at t[r]); `path` names the source in reports.
  ActuationTable(std::vector<double> t, const MatX& tau, std::string path);

  void operator()(double t, VecX& tau) const;  // no allocation
  VecX largest() const;                        // max over the rows of |τ_i|, per coordinate
  double t_first() const { return t_.front(); }
  double t_last() const { return t_.back(); }
  const std::string& path() const { return path_; }

 private:
  void reserve_rows(std::size_t rows, double memory_given);
  std::string path_;
  int n_ = 0;
  std::vector<double> t_;
  std::vector<double> tau_;  // n x samples, column-major: the n τ of row r from r n
};

}  // namespace femdyn
