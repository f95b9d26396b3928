// The trajectory CSV every command writes (femdyn simulate, study): one row per output time,
//   t, q_<c>…, qd_<c>…, kinetic, potential, total, work
// with the coordinate names from the model, energies in J (core/dynamics/equations.hpp energy())
// and work = W, the work done by the non-conservative forces since t = 0 (sim/motion.hpp), so that
// total(t) − total(0) = work(t) up to the integration error. Full double precision. The header's
// fields are quoted where a name needs it (RFC 4180, io/csv.hpp): a coordinate "a,b" is the one
// column "q_a,b".
#pragma once
#include <ostream>
#include <string>
#include <vector>

#include "core/dynamics/equations.hpp"

namespace femdyn {

void write_trajectory_header(std::ostream& out, const Model& model);
// y = (q, q̇, W) as the integrators hold it.
void write_trajectory_row(std::ostream& out, double t, const VecX& y, const Energy& E);

// A trajectory CSV read back: the header's column names and one row of numbers per line.
struct TrajectoryTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
};
// From the file's text; `source` names it in errors ("FILE:LINE: column 3: 'x' is not a
// number"; a row with another number of columns than the header).
TrajectoryTable read_trajectory_csv(const std::string& text, const std::string& source);

}  // namespace femdyn
