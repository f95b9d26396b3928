#include "elements/rigid_body.hpp"

#include "core/spatial/inertia.hpp"
#include "elements/lumped_point.hpp"
#include "elements/rotary_node.hpp"

namespace femdyn {

void RigidBodyShorthand::point_rotary(double m, const Vec3& c, const Mat3& I, ElementSink& sink) {
  sink.add(std::make_unique<LumpedPoint>(c, m), {"com"});
  sink.add(std::make_unique<RotaryNode>(c, I), {"com"});
}

void RigidBodyShorthand::from_params(const Params& p, ElementSink& sink) {
  p.allow_only({"type", "mass", "com", "inertia", "equivalent"});
  const double m = p.positive("mass");
  const Vec3 c = p.vec3_or("com", Vec3::Zero());
  const Mat3 I = p.inertia("inertia");
  if (auto problem = inertia_problem(I)) p.fail("inertia", *problem);
  const std::string how = p.has("equivalent") ? p.string("equivalent") : "point_rotary";
  if (how == "point_rotary") {
    point_rotary(m, c, I, sink);
  } else if (how == "four_points") {
    const auto pts = equimomental_points(m, c, I);
    if (!pts)
      p.fail("inertia",
             "four equimomental points need a strictly physical inertia "
             "(positive definite pseudo-inertia); use point_rotary");
    static const char* const labels[4] = {"p1", "p2", "p3", "p4"};
    for (int i = 0; i < 4; ++i)
      sink.add(std::make_unique<LumpedPoint>((*pts)[i], m / 4), {labels[i]});
  } else {
    p.fail("equivalent", "expected \"point_rotary\" or \"four_points\", got \"" + how + "\"");
  }
}

}  // namespace femdyn
