// The motion a page shows: the model's configuration q at a list of times, from a trajectory
// CSV of `femdyn simulate` (io/trajectory_csv.hpp) or one posture, with the energy balance at
// each time. At most frame_limit(bodies) frames are kept (evenly spaced rows, the first and the
// last always): kMaxFrames, fewer for a model of many bodies so that a page holds at most
// kMaxPoses body poses (10,000 bodies × 1,500 frames, 15 M poses, took 2.7 GB and aborted).
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include "core/model/model.hpp"
#include "io/trajectory_csv.hpp"

namespace femdyn::view {

inline constexpr std::size_t kMaxFrames = 1500;
inline constexpr std::size_t kMaxPoses = 1'000'000;
inline std::size_t frame_limit(std::size_t bodies) {
  return std::clamp<std::size_t>(kMaxPoses / std::max<std::size_t>(bodies, 1), 2, kMaxFrames);
}

struct MotionFrame {
  double t = 0;
  VecX q;  // n_q
  double kinetic = 0, potential = 0, work = 0;
};

struct Motion {
  std::vector<MotionFrame> frames;
  std::size_t rows = 1;       // the trajectory's rows, of which `frames` keeps some
  bool trajectory = false;    // from a trajectory (else one posture)
  std::string energy_source;  // "trajectory" (its columns) or "computed" (core energy())
};

// One posture q (n_q, checked by the caller) at rest: its energy is the potential alone.
Motion posture(const Model& model, const VecX& q);

// The rows of a trajectory table: t and every q_<name> of the model are required (finite, t
// never decreasing, quaternions of norm 1 within 1e-6); kinetic, potential and work are taken
// when all three are there, else the energy is computed from q and the qd_<name> columns (zero
// rates without them). Errors are ModelError naming `source` and the row or column.
Motion trajectory(const Model& model, const TrajectoryTable& table, const std::string& source);

// The same from a file (io/input_file.hpp reads it).
Motion read_trajectory(const Model& model, const std::string& path);

}  // namespace femdyn::view
