#include "io/trajectory_csv.hpp"

#include <charconv>

namespace femdyn {
namespace {

void put(std::ostream& out, double x) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);  // shortest round-trip form
  out.write(buf, r.ptr - buf);
}

}  // namespace

void write_trajectory_header(std::ostream& out, const Model& m) {
  out << "t";
  for (const auto& c : m.coordinate_names) out << ",q_" << c;
  for (const auto& c : m.coordinate_names) out << ",qd_" << c;
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

}  // namespace femdyn
