#include "models/hand.hpp"

#include <numbers>

namespace femdyn {

void append_hand(const Params& p, const std::string& parent, const Json& mount,
                 FingeredParts& parts) {
  Json& bodies = parts.bodies;
  p.allow_only({"thumb", "wrist", "finger", "palm_mass"});
  const bool thumb = p.boolean_or("thumb", true);
  const bool wrist = p.boolean_or("wrist", true);
  const double palm_mass = p.has("palm_mass") ? p.positive("palm_mass") : 0.35;
  const FingerParams f = p.has("finger") ? FingerParams::from(p.child("finger")) : FingerParams{};
  if (f.paper_lumping) p.fail("finger", "a hand uses the exact lumping");

  // Palm: an aluminium plate 90 x 100 x 20 mm about its centre, 50 mm above the wrist.
  const double m = palm_mass, a = 0.09, b = 0.02, c = 0.10;
  const Json palm_body = {{"type", "rigid_body"},
                          {"mass", m},
                          {"com", {0, 0, 0.05}},
                          {"inertia",
                           {{"ixx", m * (b * b + c * c) / 12},
                            {"iyy", m * (a * a + c * c) / 12},
                            {"izz", m * (a * a + b * b) / 12}}}};
  std::string palm_parent = parent;
  if (wrist) {
    // Wrist: deviation about z then flexion about x; the carpal link is small.
    bodies.push_back(
        {{"name", "carpus"},
         {"parent", parent},
         {"joint",
          {{"name", "wrist_deviation"},
           {"type", "revolute"},
           {"axis", {0, 0, 1}},
           {"limits", {-0.4, 0.4}},
           {"origin", mount}}},
         {"elements",
          Json::array({{{"type", "rigid_body"},
                        {"mass", 0.05},
                        {"com", {0, 0, 0.005}},
                        {"inertia", {{"ixx", 1e-5}, {"iyy", 1e-5}, {"izz", 1e-5}}}}})}});
    palm_parent = "carpus";
  }
  bodies.push_back(
      {{"name", "palm"},
       {"parent", palm_parent},
       {"joint", wrist ? Json{{"name", "wrist_flexion"},
                              {"type", "revolute"},
                              {"axis", {1, 0, 0}},
                              {"limits", {-1.0, 1.0}},
                              {"origin", {{"xyz", {0, 0, 0.01}}}}}
                       : Json{{"name", "palm_mount"}, {"type", "fixed"}, {"origin", mount}}},
       {"elements", Json::array({palm_body})}});
  // Fingers along the top edge of the palm (z = 0.1), slightly splayed; the palm normal is y.
  const double half_pi = std::numbers::pi / 2;
  const char* names[] = {"index_", "middle_", "ring_", "little_"};
  const double x[] = {0.033, 0.011, -0.011, -0.033}, splay[] = {0.08, 0.0, -0.06, -0.12};
  for (int i = 0; i < 4; ++i)
    // Finger frame: abduction axis along the palm's z (the fingers' pointing direction at
    // rest is +z). The plugin's base yaw of π/2 makes the flexion axis the palm's x.
    append_finger(f, names[i], "palm", Vec3(x[i], 0, 0.10), Vec3(0, 0, half_pi + splay[i]), parts);
  if (thumb)
    // Thumb on the side of the palm, its abduction axis tilted towards the palm normal.
    append_finger(f, "thumb_", "palm", Vec3(0.045, 0.01, 0.03), Vec3(0, 0.9, half_pi - 0.6), parts);
}

Json dexterous_hand(const Params& p) {
  FingeredParts parts;
  append_hand(p, "world", {{"xyz", {0, 0, 0}}}, parts);
  return fingered_model("dexterous hand", parts);
}

}  // namespace femdyn
