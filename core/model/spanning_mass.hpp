// A spanning element's mass on the body-level routes (Model::spanning_masses; its share of the
// equations is core/dynamics/span_inertia.hpp's).
#pragma once
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn {

// One spanning element on the body-level routes: its nodes (body, point in the body's axes) and
// its mass on their translations (3k × 3k).
struct SpanningMass {
  std::vector<int> body;
  std::vector<Vec3> point;
  MatX mass;
};

}  // namespace femdyn
