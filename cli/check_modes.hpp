// femdyn check's natural modes: the oscillatory modes of the linearisation about the static
// equilibrium (sim/statics.hpp) at q̇ = 0, lowest first, with the joint each moves most. An
// elastic model's frequencies (docs/flexible.md); a pendulum's small swings.
#pragma once
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "sim/stability.hpp"

namespace femdyn::cli {

struct NaturalModes {
  std::vector<Mode> oscillatory;  // ascending in ω
  int unstable = 0;               // modes with Re λ > 0 at the equilibrium (it is not stable)
  int rigid = 0;  // rigid-body modes, ω = 0: coordinates no spring holds (a free base, a joint)
  std::string missing;  // why none are listed (no equilibrium, closed loops), or ""
};

// At the equilibrium the model file `path` (loaded as `a` says) rests in under its springs,
// gravity and loads; τ = 0.
NaturalModes natural_modes(const Args& a, const Model& m);
// One line: "natural modes at rest: K oscillatory; lowest ω (Hz) in joint '…', …; highest …".
std::string natural_modes_text(const Model& m, const NaturalModes& modes);
Json natural_modes_json(const Model& m, const NaturalModes& modes);

}  // namespace femdyn::cli
