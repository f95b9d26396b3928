// rigid_body: shorthand for a body given by mass m, centre of mass c and inertia I_c about c
// (body frame), as in URDF. Loading turns it into equivalent elements with the same
// pseudo-inertia P:
//   "equivalent": "point_rotary" (default)  lumped_point m at c + rotary_node I_c at c
//   "equivalent": "four_points"             four lumped points m/4 (core/spatial/inertia.hpp)
#pragma once
#include "elements/registry.hpp"

namespace femdyn {

struct RigidBodyShorthand {
  static void from_params(const Params& p, ElementSink& sink);
  // The default variant: a lumped point m and a rotary node I (centroidal, body axes) at the
  // centre of mass c, both at the node "com".
  static void point_rotary(double m, const Vec3& c, const Mat3& I, ElementSink& sink);
};

}  // namespace femdyn
