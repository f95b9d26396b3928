#include "models/random_tree.hpp"

#include <cmath>
#include <random>

#include "core/spatial/math.hpp"

namespace femdyn {

Json random_tree(const Params& p) {
  p.allow_only({"seed", "bodies", "branching", "prismatic"});
  const double seed = p.has("seed") ? p.number("seed") : 1.0;
  if (seed < 0 || seed != std::floor(seed)) p.fail("seed", "expected an integer >= 0");
  // Checked before any cast: a double beyond unsigned's range does not convert (undefined).
  if (seed > 4294967295.0) p.fail("seed", "expected an integer <= 4294967295");
  const double count = p.has("bodies") ? p.number("bodies") : 10.0;
  if (count < 1 || count > 10000 || count != static_cast<int>(count))
    p.fail("bodies", "expected an integer from 1 to 10000");
  const double branching = p.number_or("branching", 0.0);
  if (!(branching >= 0 && branching <= 1)) p.fail("branching", "expected a number in [0, 1]");
  const bool prismatic = p.boolean_or("prismatic", true);

  std::mt19937 rng(static_cast<unsigned>(seed));
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.2, 1.0);
  const auto vec = [](double x, double y, double z) { return Json::array({x, y, z}); };
  Json bodies = Json::array();
  for (int b = 0; b < static_cast<int>(count); ++b) {
    int parent = b - 1;
    if (branching > 0 && b > 1 && pos(rng) < 0.2 + 0.8 * branching)
      parent = static_cast<int>(rng() % b);
    const bool slide = prismatic && rng() % 4 == 0;
    // Physical inertia: principal moments (b + c, a + c, a + b) of three positive second
    // moments a, b, c (the triangle inequality holds), turned by a random rotation.
    const double sa = pos(rng), sb = pos(rng), sc = pos(rng), mass = pos(rng);
    const Vec3 principal(sb + sc, sa + sc, sa + sb);
    // (Drawn last to first, the order GCC evaluated Vec3(u(rng), u(rng), u(rng)) in before, so
    // that a seed keeps its tree; a constructor's arguments are not sequenced.)
    const double t2 = u(rng), t1 = u(rng), t0 = u(rng);
    const Mat3 R = rpy_to_rotation(Vec3(t0, t1, t2) * 3);
    const Mat3 I = 0.05 * mass * R * principal.asDiagonal() * R.transpose();
    // (Arguments in separate statements: their order of evaluation is the random sequence.)
    const double a0 = u(rng), a1 = u(rng), a2 = u(rng);
    const double x0 = u(rng), x1 = u(rng), x2 = u(rng);
    const double r0 = u(rng), r1 = u(rng), r2 = u(rng);
    const double c0 = u(rng), c1 = u(rng), c2 = u(rng);
    bodies.push_back(
        {{"name", "b" + std::to_string(b)},
         {"parent", parent < 0 ? std::string("world") : "b" + std::to_string(parent)},
         {"joint",
          {{"name", "j" + std::to_string(b)},
           {"type", slide ? "prismatic" : "revolute"},
           {"axis", vec(a0, a1, a2)},
           {"origin", {{"xyz", vec(0.5 * x0, 0.5 * x1, 0.5 * x2)}, {"rpy", vec(r0, r1, r2)}}}}},
         {"elements",
          Json::array({{{"type", "rigid_body"},
                        {"mass", mass},
                        {"com", vec(0.3 * c0, 0.3 * c1, 0.3 * c2)},
                        {"inertia",
                         {vec(I(0, 0), I(0, 1), I(0, 2)), vec(I(1, 0), I(1, 1), I(1, 2)),
                          vec(I(2, 0), I(2, 1), I(2, 2))}}}})}});
  }
  return {{"name", "random tree " + std::to_string(static_cast<unsigned>(seed))},
          {"gravity", vec(0, 0, -9.81)},
          {"bodies", bodies}};
}

}  // namespace femdyn
