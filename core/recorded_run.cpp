#include "core/recorded_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace femdyn {

RecordedRun run_recorded(Integrator& integ, double t_end, long every,
                         const std::vector<double>* times,
                         const std::function<void(const Integrator&, const Energy&)>& row,
                         const std::function<bool(double t)>& stop) {
  RecordedRun r;
  r.initial = integ.motion().energy_at(integ.y().data());
  r.scale = std::max(std::abs(r.initial.total()), std::abs(r.initial.kinetic));
  const auto output = [&] {
    const Energy E = integ.motion().energy_at(integ.y().data());
    r.max_balance = std::max(r.max_balance, std::abs(E.total() - r.initial.total() - integ.work()));
    r.scale = std::max({r.scale, std::abs(E.total()), E.kinetic});
    row(integ, E);
    ++r.rows;
  };
  const auto begin = std::chrono::steady_clock::now();
  if (times) {
    for (double t : *times) {
      if (t > integ.t()) r.status = integ.advance_to(t);
      if (!r.status.ok) break;
      output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  } else {
    output();
    for (long step = 1; integ.t() < t_end; ++step) {
      r.status = integ.step();
      if (!r.status.ok) break;
      if (step % every == 0 || integ.t() >= t_end) output();
      if ((r.interrupted = stop(integ.t()))) break;
    }
  }
  r.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return r;
}

bool conservative(const Model& model, bool driven) {
  bool c = !driven && model.torques.empty();
  for (const Body& b : model.bodies) c = c && b.joint.damping == 0;
  return c;
}

}  // namespace femdyn
