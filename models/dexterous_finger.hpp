// The dexterous finger of the paper (Ly Bohan et al., §IV): a base unit turning about the palm
// normal (abduction θ1), then proximal, middle and distal knuckles flexing (θ2, θ3, θ4) about
// an axis perpendicular to the abduction axis that turns with θ1. Each unit is a space bar
// lumped to its two end nodes. Body frames: x is the flexion axis, knuckles run along +z, the
// base unit runs radially outward along −y; at q = 0 the finger points along the palm normal.
// Optional coupling θ4 = ratio·θ3 + offset. Defaults and their reasoning: docs/finger.md.
#pragma once
#include <array>
#include <string>

#include "io/params.hpp"

namespace femdyn {

struct FingerParams {
  std::array<double, 4> length{0.015, 0.045, 0.030, 0.022};  // a1..a4, m
  std::array<double, 4> width{0.012, 0.012, 0.011, 0.010};   // along the flexion axis, m
  std::array<double, 4> height{0.010, 0.010, 0.009, 0.008};  // across it, m
  double density = 2700;                                     // aluminium 6061, kg/m³
  std::array<std::array<double, 2>, 4> limits{{{-0.35, 0.35}, {-0.2, 1.6}, {0, 1.75}, {0, 1.4}}};
  std::array<double, 4> stiffness{0, 0, 0, 0};  // N·m/rad, about the rest angles
  std::array<double, 4> rest{0, 0, 0, 0};
  std::array<double, 4> damping{0, 0, 0, 0};  // N·m·s/rad
  bool coupled = false;                       // θ4 = ratio·θ3 + offset, or
  double ratio = 1.0, offset = 0.0;
  Json law;  // {"four_bar" | "polynomial" | "spline": …}: θ4 = law(θ3) (docs/model-format.md)
  double coupler_mass = 0;  // with a four_bar: its coupler as a rod between the two levers
  bool closed_by_constraint = false;  // with a four_bar: "closure": "constraint" (docs/loops.md)
  Vec3 tip_force = Vec3::Zero();      // constant external force at the fingertip (world, N)
  bool paper_lumping = false;         // the paper's own discretisation (table N_m, lumping)

  static FingerParams from(const Params& p);
};

// The parts of a model document that fingers add to: JSON arrays of the model format.
struct FingeredParts {
  Json bodies = Json::array(), couplings = Json::array(), loads = Json::array(),
       frames = Json::array(), constraints = Json::array();
};

// Appends the finger's bodies (names prefixed), its base joint at `xyz`/`rpy` in `parent`, its
// coupling (a law, or a coupler body with its loop constraint and the frames it joins) and tip
// load.
void append_finger(const FingerParams& f, const std::string& prefix, const std::string& parent,
                   const Vec3& xyz, const Vec3& rpy, FingeredParts& parts);

// The model document {"name", "bodies", "couplings", "loads", "frames", "constraints"} of
// fingered parts: empty lists left out, a frame "<prefix>tip" at each fingertip (node b of each
// "<prefix>distal") before the parts' own frames.
Json fingered_model(const std::string& name, const FingeredParts& parts);

Json dexterous_finger(const Params& params);

}  // namespace femdyn
