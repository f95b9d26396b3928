// A hand composed from the dexterous finger plugin: a palm on an optional 2-DOF wrist
// (flexion, deviation) carrying four fingers and, optionally, an opposed thumb. Every finger is
// the same `dexterous_finger` (params under "finger"), mounted at its own place on the palm.
#pragma once
#include "models/dexterous_finger.hpp"

namespace femdyn {

Json dexterous_hand(const Params& params);

// Appends the hand's parts, its first joint (the wrist's deviation, or the palm's fixed mount)
// under `parent` at `mount` ({"xyz", "rpy"}, the joint's origin).
void append_hand(const Params& params, const std::string& parent, const Json& mount,
                 FingeredParts& parts);

}  // namespace femdyn
