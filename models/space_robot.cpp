#include "models/space_robot.hpp"

#include <numbers>

#include "models/dexterous_finger.hpp"
#include "models/hand.hpp"

namespace femdyn {

namespace {

// One link of the arm: its joint's origin in the previous link (xyz, rpy), the link's mass,
// centre of mass and principal inertia about it (body axes), and the joint's limit ±limit.
struct ArmLink {
  Vec3 xyz, rpy;
  double mass;
  Vec3 com, inertia;
  double limit;
};

// KUKA LBR iiwa, the "simplified" URDF of the rbd-benchmarks set (Neuman et al., IROS 2019),
// links 1–7; every joint is revolute about its frame's z.
constexpr double kPi = std::numbers::pi, kHalfPi = kPi / 2;
const ArmLink kArm[] = {
    {{0, 0, 0.1575}, {0, 0, 0}, 4.0, {0, -0.03, 0.12}, {0.1, 0.09, 0.02}, 2.96705972839},
    {{0, 0, 0.2025},
     {kHalfPi, 0, -kPi},
     4.0,
     {0.0003, 0.059, 0.042},
     {0.05, 0.018, 0.044},
     2.09439510239},
    {{0, 0.2045, 0}, {kHalfPi, 0, -kPi}, 3.0, {0, 0.03, 0.13}, {0.08, 0.075, 0.01}, 2.96705972839},
    {{0, 0, 0.2155}, {kHalfPi, 0, 0}, 2.7, {0, 0.067, 0.034}, {0.03, 0.01, 0.029}, 2.09439510239},
    {{0, 0.1845, 0},
     {kHalfPi, 0, -kPi},
     1.7,
     {0.0001, 0.021, 0.076},
     {0.02, 0.018, 0.005},
     2.96705972839},
    {{0, 0, 0.2155},
     {kHalfPi, 0, 0},
     1.8,
     {0, 0.0006, 0.0004},
     {0.005, 0.0036, 0.0047},
     2.09439510239},
    {{0, 0.081, 0}, {kHalfPi, 0, -kPi}, 0.3, {0, 0, 0.02}, {0.001, 0.001, 0.001}, 3.05432619099},
};

Json box_body(double m, const Vec3& size) {
  const double a = size.x() * size.x(), b = size.y() * size.y(), c = size.z() * size.z();
  return {{"type", "rigid_body"},
          {"mass", m},
          {"inertia",
           {{"ixx", m * (b + c) / 12}, {"iyy", m * (a + c) / 12}, {"izz", m * (a + b) / 12}}}};
}

}  // namespace

Json space_robot(const Params& p) {
  p.allow_only({"satellite_mass", "satellite_size", "hand"});
  const double mass = p.has("satellite_mass") ? p.positive("satellite_mass") : 200.0;
  const Vec3 size = p.vec3_or("satellite_size", Vec3(1.2, 1.0, 1.0));
  if ((size.array() <= 0).any()) p.fail("satellite_size", "every side must be > 0");

  FingeredParts parts;
  Json& bodies = parts.bodies;
  // The satellite: a uniform box on a free joint, its centre at the body origin.
  bodies.push_back({{"name", "satellite"},
                    {"parent", "world"},
                    {"joint", {{"type", "free"}}},
                    {"elements", Json::array({box_body(mass, size)})}});
  // The arm, mounted at the centre of the satellite's +z face.
  std::string parent = "satellite";
  for (int k = 0; k < 7; ++k) {
    const ArmLink& L = kArm[k];
    const Vec3 xyz = k == 0 ? L.xyz + Vec3(0, 0, size.z() / 2) : L.xyz;
    const std::string name = "link" + std::to_string(k + 1);
    bodies.push_back(
        {{"name", name},
         {"parent", parent},
         {"joint",
          {{"name", "joint" + std::to_string(k + 1)},
           {"type", "revolute"},
           {"axis", {0, 0, 1}},
           {"limits", {-L.limit, L.limit}},
           {"origin", {{"xyz", vec3_json(xyz)}, {"rpy", vec3_json(L.rpy)}}}}},
         {"elements",
          Json::array(
              {{{"type", "rigid_body"},
                {"mass", L.mass},
                {"com", vec3_json(L.com)},
                {"inertia",
                 {{"ixx", L.inertia.x()}, {"iyy", L.inertia.y()}, {"izz", L.inertia.z()}}}}})}});
    parent = name;
  }
  // The hand at the flange; by default without its own wrist (the arm has one).
  Json hand = p.has("hand") ? p.json().at("hand") : Json::object();
  if (!hand.is_object()) p.fail("hand", "expected an object of dexterous_hand params");
  if (!hand.contains("wrist")) hand["wrist"] = false;
  append_hand(Params(hand, p.path("hand")), parent, {{"xyz", {0, 0, 0.045}}}, parts);

  return fingered_model("space robot", parts);
}

}  // namespace femdyn
