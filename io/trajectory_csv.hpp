// The trajectory CSV every command writes (femdyn simulate, study): one row per output time,
//   t, q_<c>…, qd_<c>…, kinetic, potential, total, work
// with the coordinate names from the model, energies in J (core/equations.hpp energy()) and
// work = W, the work done by the non-conservative forces since t = 0 (core/motion.hpp), so
// that total(t) − total(0) = work(t) up to the integration error. Full double precision.
#pragma once
#include <ostream>

#include "core/equations.hpp"

namespace femdyn {

void write_trajectory_header(std::ostream& out, const Model& model);
// y = (q, q̇, W) as the integrators hold it.
void write_trajectory_row(std::ostream& out, double t, const VecX& y, const Energy& E);

}  // namespace femdyn
