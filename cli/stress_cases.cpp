#include "cli/stress_cases.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>

#include "validation/stress.hpp"

namespace femdyn::cli {
namespace {

// A rigid link of length L and mass m along x: centre of mass at L/2, a solid rod of radius
// r = L/20 (r = 0: a thin rod, no inertia about its axis).
Json rod(double m, double L, double r) {
  const double ax = 0.5 * m * r * r, tr = m * (3 * r * r + L * L) / 12;
  return {{"type", "rigid_body"},
          {"mass", m},
          {"com", {L / 2, 0, 0}},
          {"inertia", {{"ixx", ax}, {"iyy", tr}, {"izz", tr}}}};
}

Json joint(const std::string& name, const std::string& type, Json axis, Json xyz) {
  return {{"name", name}, {"type", type}, {"axis", axis}, {"origin", {{"xyz", xyz}}}};
}

// (Lists as std::vector: a braced list of one Json is that Json to clang, an array of it to GCC.)
Json body(const std::string& name, const std::string& parent, Json j,
          const std::vector<Json>& elements) {
  return {{"name", name}, {"parent", parent}, {"joint", j}, {"elements", Json(elements)}};
}

Json model(const std::string& name, const std::vector<Json>& bodies, double gravity = 9.81) {
  return {{"name", name}, {"gravity", {0, 0, -gravity}}, {"bodies", Json(bodies)}};
}

// A chain of links along x with the given masses and lengths; joint axes alternate y, z.
Json chain(const std::string& name, const std::vector<double>& mass,
           const std::vector<double>& length) {
  std::vector<Json> bodies;
  double offset = 0;
  for (std::size_t i = 0; i < mass.size(); ++i) {
    const std::string self = "link" + std::to_string(i + 1);
    const std::string parent = i ? "link" + std::to_string(i) : "world";
    bodies.push_back(body(self, parent,
                          joint("j" + std::to_string(i + 1), "revolute",
                                i % 2 ? Json{0, 0, 1} : Json{0, 1, 0}, {offset, 0, 0}),
                          {rod(mass[i], length[i], length[i] / 20)}));
    offset = length[i];
  }
  return model(name, bodies);
}

// One arm of inertia 1 kg·m² on a joint spring of frequency ω and damping ratio ζ, no gravity.
Json spring(double w, double zeta) {
  Json j = joint("theta", "revolute", {0, 1, 0}, {0, 0, 0});
  j["spring"] = {{"stiffness", w * w}};
  j["damping"] = 2 * zeta * w;
  return model(
      "spring",
      {body("arm", "world", j, {{{"type", "lumped_point"}, {"node", {1, 0, 0}}, {"mass", 1.0}}})},
      0);
}

// A slender steel bar (1 m, 1 mm², section Iy = Iz = 1e-13 m⁴) by section: its lumped rotary
// inertia J_rot is negative across the bar. Two joints: perpendicular, then along the bar.
Json slender_bars() {
  Json bar = {{"type", "space_bar"}, {"nodes", {{0, 0, 0}, {1, 0, 0}}},
              {"density", 7800},     {"area", 1e-6},
              {"Iy", 1e-13},         {"Iz", 1e-13}};
  return model(
      "slender bars",
      {body("bar1", "world", joint("perpendicular", "revolute", {0, 1, 0}, {0, 0, 0}), {bar}),
       body("bar2", "bar1", joint("along", "revolute", {1, 0, 0}, {1, 0, 0}),
            {bar, rod(1e-3, 0.01, 0.005)})});
}

// A planar four-bar in the x-y plane, joints about z: ground A = 0 to D = (d, 0), crank AB (a),
// coupler BC (b), rocker CD (c), 1 kg rods; the tree is crank → coupler → rocker and the loop is
// closed at D by a ball between the rocker's tip and the world: in the plane (`normal`, 2
// equations) or in space (3, one of them redundant: the planar motion never moves z).
struct FourBar {
  double a, b, c, d;
};

Json fourbar(const std::string& name, const FourBar& f, double gravity, bool planar) {
  Json j = {{"name", name},
            {"gravity", {0, -gravity, 0}},
            {"bodies",
             {body("crank", "world", joint("crank", "revolute", {0, 0, 1}, {0, 0, 0}),
                   {rod(1, f.a, f.a / 20)}),
              body("coupler", "crank", joint("coupler", "revolute", {0, 0, 1}, {f.a, 0, 0}),
                   {rod(1, f.b, f.b / 20)}),
              body("rocker", "coupler", joint("rocker", "revolute", {0, 0, 1}, {f.b, 0, 0}),
                   {rod(1, f.c, f.c / 20)})}}};
  Json ball = {{"name", "D"},
               {"type", "ball"},
               {"a", {{"body", "rocker"}, {"xyz", {f.c, 0, 0}}}},
               {"b", {{"body", "world"}, {"xyz", {f.d, 0, 0}}}}};
  if (planar) ball["normal"] = {0, 0, 1};
  j["constraints"] = Json::array({ball});
  return j;
}

// The four-bar's points at crank angle θ: B = a (cos θ, sin θ), and C where the circles
// |C − B| = b and |C − D| = c meet, on the side `elbow` (±1) of BD: with e = D − B, L = |e|,
// C = B + x ê + elbow √(b² − x²) ê⊥, x = (b² − c² + L²) / 2L.
struct FourBarPoints {
  double bx, by, cx, cy;
};
FourBarPoints fourbar_points(const FourBar& f, double theta, int elbow) {
  const double bx = f.a * std::cos(theta), by = f.a * std::sin(theta);
  const double ex = f.d - bx, ey = -by, L = std::hypot(ex, ey);
  const double x = (f.b * f.b - f.c * f.c + L * L) / (2 * L);
  const double y = elbow * std::sqrt(std::max(0.0, f.b * f.b - x * x));
  return {bx, by, bx + (x * ex - y * ey) / L, by + (x * ey + y * ex) / L};
}

// Its tree coordinates there (each joint's angle relative to its parent).
std::vector<double> fourbar_posture(const FourBar& f, double theta, int elbow) {
  const FourBarPoints p = fourbar_points(f, theta, elbow);
  const double coupler = std::atan2(p.cy - p.by, p.cx - p.bx);
  const double rocker = std::atan2(-p.cy, f.d - p.cx);
  return {theta, coupler - theta, rocker - coupler};
}

Json finger(double gravity) {
  return {{"model", "dexterous_finger"}, {"params", Json::object()}, {"gravity", {0, 0, -gravity}}};
}

// Closed loops (docs/loops.md): a four-bar at its dead point and one passing near its change
// point, a redundant loop under drift, and a stiff loop.
void loop_cases(std::vector<StressCase>& c, bool quick) {
  (void)quick;  // every loop case is quick (n = 3)
  {
    // Ground = crank + coupler + rocker: the only configuration is the chain stretched straight,
    // where Φ_q has rank 1 of 2 (every joint on the line AD). At rest the equations are
    // consistent; gravity then bends the chain in Φ_q's null space, which the closed chain
    // cannot follow to second order: S λ = r has no solution (a dead point).
    const FourBar f{0.3, 0.4, 0.3, 1.0};
    c.push_back({"loops",
                 "four-bar at its toggle",
                 "a four-bar whose ground equals crank + coupler + rocker (0.3 + 0.4 + 0.3 m): "
                 "stretched straight, at rest, under gravity",
                 fourbar("toggle", f, 9.81, true),
                 {0, 0, 0},
                 {},
                 0.5,
                 1e-3});
    c.back().expect = validation::kDeadPointVerdict;
  }
  {
    // Lengths 1e-4 m from a change point (a + b = c + d: every joint on one line, two branches
    // crossing): the crank turns fully and passes near that line every turn, where Φ_q's
    // σ_min/σ_max falls to about 0.02 (it goes as the square root of the 1e-4 m).
    const FourBar f{0.2, 0.5, 0.4001, 0.3};
    c.push_back({"loops",
                 "four-bar near its change point",
                 "a crank-rocker (0.2, 0.5, 0.4001 m, ground 0.3 m) 1e-4 m from the change-point "
                 "lengths, the crank turning at 10 rad/s: it passes near its flat position every "
                 "turn",
                 fourbar("near toggle", f, 0, true),
                 fourbar_posture(f, std::numbers::pi, 1),
                 {10, 0, 0},
                 1,
                 1e-4});
  }
  {
    // A parallelogram closed by a 3-D ball: 3 equations, rank 2 (the z row repeats: nothing
    // moves out of the plane). Started 1e-3 rad off the loop (assembled back), swinging under
    // gravity for 10 s: Baumgarte and the projection hold it.
    const FourBar f{0.3, 0.5, 0.3, 0.5};
    const double theta = -std::numbers::pi / 2 + 0.6;
    c.push_back({"loops",
                 "parallelogram closed by a 3-D ball",
                 "a parallelogram (0.3 m cranks, 0.5 m coupler) closed by a ball in space (3 "
                 "equations, 1 redundant), started 1e-3 rad off the loop, swinging 0.6 rad "
                 "under gravity for 10 s",
                 fourbar("parallelogram", f, 9.81, false),
                 {theta, -theta + 1e-3, theta + std::numbers::pi},
                 {},
                 10,
                 1e-3});
  }
  {
    // A stiff two-point spring (1e11 N/m) from the coupler's middle to a fixed point 0.2 m
    // away, stretched 1e-8 m: its mode dominates (ω about 9e4 rad/s, RK4's limit 3e-5 s) and is
    // linear at that amplitude, so the measured RK4 limit is the constrained linearisation's
    // 2.83/ω.
    const FourBar f{0.2, 0.5, 0.45, 0.5};
    const double theta = 2.0;
    const FourBarPoints p = fourbar_points(f, theta, 1);
    const double mx = (p.bx + p.cx) / 2, my = (p.by + p.cy) / 2;
    Json m = fourbar("stiff loop", f, 0, true);
    m["springs"] = Json::array({{{"name", "stiff"},
                                 {"a", {{"body", "coupler"}, {"xyz", {f.b / 2, 0, 0}}}},
                                 {"b", {{"body", "world"}, {"xyz", {mx, my + 0.2, 0}}}},
                                 {"stiffness", 1e11},
                                 {"rest_length", 0.2 - 1e-8}}});
    c.push_back(
        {"loops",
         "four-bar with a stiff spring",
         "a four-bar (0.2, 0.5, 0.45 m, ground 0.5 m) with a 1e11 N/m spring on its coupler, "
         "stretched 1e-8 m: a stiff undamped loop mode",
         m,
         fourbar_posture(f, theta, 1),
         {},
         0.005,
         1e-4});
    c.back().expect = "stiff and undamped";
  }
}

}  // namespace

// A 2 m aluminium tube (100 mm, 3 mm wall) in 8 parts on a hub spun at 2 rad/s, in zero
// gravity: its axial modes reach about 4e4 rad/s (2 c / Δ, c = √(E/ρ) = 5050 m/s, Δ = 0.25 m),
// undamped, or damped by c = β k (ζ = β ω / 2: 2 at the top for β = 1e-4).
void flexible_cases(std::vector<StressCase>& c) {
  for (const double beta : {0.0, 1e-4}) {
    Json bar = {{"name", "tube"},
                {"parent", "hub"},
                {"length", 2.0},
                {"segments", 8},
                {"section",
                 {{"E", 6.89e10},
                  {"G", 2.6e10},
                  {"density", 2700},
                  {"area", 9.142e-4},
                  {"Iy", 1.0762e-6},
                  {"Iz", 1.0762e-6},
                  {"J", 2.1525e-6}}}};
    if (beta > 0) bar["damping"] = {{"stiffness_proportional", beta}};
    Json m = model("flexible tube",
                   {body("hub", "world", joint("hub", "revolute", {0, 0, 1}, {0, 0, 0}),
                         {rod(0.2, 1.0, 0.02)})},
                   0.0);
    m["flexible_bars"] = Json::array({bar});
    std::vector<double> qd0(33, 0.0);
    qd0[0] = 2;
    c.push_back({"flexible",
                 beta > 0 ? "aluminium tube, damped" : "aluminium tube",
                 "a 2 m aluminium tube in 8 parts (bending, torsion, stretch) on a hub spun at "
                 "2 rad/s" +
                     std::string(beta > 0 ? ", Rayleigh damping c = 1e-4 s k" : ", undamped"),
                 m,
                 {},
                 qd0,
                 0.01,
                 1e-4});
    c.back().expect = beta > 0 ? "stable only with bdf" : "stiff and undamped";
  }
}

std::vector<StressCase> stress_cases(bool quick) {
  std::vector<StressCase> c;
  // Stiff joint springs: ω = 1e1 … 1e5 rad/s, ζ = 0 … 100.
  for (double w : quick ? std::vector<double>{1e1, 1e5} : std::vector<double>{1e1, 1e3, 1e5})
    for (double zeta : quick ? std::vector<double>{0, 100} : std::vector<double>{0, 1, 100}) {
      StressCase s{"springs",
                   "spring w=" + format_number(w, "%g") + " zeta=" + format_number(zeta, "%g"),
                   "1 kg·m² arm on a joint spring of ω = " + format_number(w, "%g") +
                       " rad/s, damping ratio " + format_number(zeta, "%g"),
                   spring(w, zeta),
                   {0.1},
                   {0}};
      s.t_end = w >= 1e4 ? 0.02 : w >= 1e3 ? 0.2 : 2;
      s.dt = 1e-4;
      // The stiffest mode: ω undamped, the fast real root ω(ζ + √(ζ² − 1)) overdamped; stiff
      // when RK4's limit (2.83/ω, 2.785/|λ|) is below the 1e-4 s of an ordinary step.
      const double fastest = zeta >= 1 ? w * (zeta + std::sqrt(zeta * zeta - 1)) : w;
      s.expect = 2.8 / fastest >= 1e-4 ? "stable"
                 : zeta >= 0.5         ? "stable only with bdf"
                                       : "stiff and undamped";
      c.push_back(s);
    }
  // Mass and length ratios in one chain.
  c.push_back({"ratios",
               "mass ratio 1e6",
               "4 links of 0.3 m, masses 1, 1e6, 1, 1e-6 kg (neighbour ratios up to 1e6)",
               chain("mass ratios", {1, 1e6, 1, 1e-6}, {0.3, 0.3, 0.3, 0.3}),
               {0.3, -0.5, 0.7, 0.2},
               {},
               0.5,
               1e-3});
  c.back().expect = "ill-conditioned";
  c.push_back({"ratios",
               "lengths 1e-4 to 10 m",
               "4 links of 1e-4, 1e-2, 1 and 10 m, 1 kg each",
               chain("length ratios", {1, 1, 1, 1}, {1e-4, 1e-2, 1, 10}),
               {0.3, -0.5, 0.7, 0.2},
               {},
               0.5,
               1e-3});
  // Fast joints and a fast gyroscopic rotor.
  c.push_back({"speeds",
               "joints at 1e3 rad/s",
               "double pendulum of 0.5 m rods started at 1000 rad/s",
               chain("fast double pendulum", {1, 0.5}, {0.5, 0.5}),
               {0.2, 0.4},
               {1000, -1000},
               0.01,
               1e-5});
  {
    Json rotor = {{"type", "rigid_body"},
                  {"mass", 1.0},
                  {"com", {0, 0, 0}},
                  {"inertia", {{"ixx", 0.02}, {"iyy", 0.01}, {"izz", 0.01}}}};
    Json m =
        model("gyroscope",
              {body("gimbal", "world", joint("precession", "revolute", {0, 0, 1}, {0, 0, 0}),
                    {rod(0.2, 0.1, 0.005)}),
               body("fork", "gimbal", joint("nutation", "revolute", {0, 1, 0}, {0.1, 0, 0}),
                    {rod(0.1, 0.05, 0.005)}),
               body("rotor", "fork", joint("spin", "revolute", {1, 0, 0}, {0.05, 0, 0}), {rotor})});
    c.push_back({"speeds",
                 "gyroscopic rotor at 1e3 rad/s",
                 "a disc spinning at 1000 rad/s in a two-axis gimbal: nutation at ~2000 rad/s",
                 m,
                 {0, 0.2, 0},
                 {1, 0, 1000},
                 0.05,
                 1e-5});
  }
  // Slender bars with negative lumped rotary inertia.
  c.push_back({"slender bars",
               "slender bars, axes perpendicular and along",
               "two 1 m steel bars of 1 mm² by section (J_rot negative): the second turns about "
               "its own axis",
               slender_bars(),
               {0.3, 0.2},
               {0, 5},
               0.5,
               1e-4});
  // Near-singular postures.
  c.push_back({"postures",
               "finger stretched",
               "the paper's finger fully stretched (q = 0) under gravity",
               finger(9.81),
               {0, 0, 0, 0},
               {0, 0.5, 0.5, 0.5},
               0.2,
               1e-3});
  {
    Json m = model(
        "aligned axes",
        {body("b1", "world", joint("yaw", "revolute", {0, 0, 1}, {0, 0, 0}), {rod(1, 0.5, 0.025)}),
         body("b2", "b1", joint("pitch", "revolute", {0, 1, 0}, {0, 0, 0.5}), {rod(1, 0.5, 0.025)}),
         body("b3", "b2", joint("roll", "revolute", {0, 0, 1}, {0, 0, 0}),
              {rod(0.5, 0.3, 0.015)})});
    c.push_back({"postures",
                 "two joint axes aligned",
                 "yaw and roll axes collinear at pitch = 0 (a wrist singularity)",
                 m,
                 {0, 0, 0},
                 {0.5, 0.5, 0.5},
                 0.5,
                 1e-3});
  }
  {
    Json slider = {{"type", "rigid_body"},
                   {"mass", 1.0},
                   {"com", {0, 0, 0}},
                   {"inertia", {{"ixx", 1e-6}, {"iyy", 1e-6}, {"izz", 1e-6}}}};
    Json m = model(
        "slider at zero",
        {body("table", "world", joint("spin", "revolute", {0, 0, 1}, {0, 0, 0}), {}),
         body("slider", "table", joint("reach", "prismatic", {1, 0, 0}, {0, 0, 0}), {slider})});
    // Started 1 mm off the axis, spinning: the slider is flung out (r grows about as cosh 5t
    // while the spin lasts), so M^s goes from nearly singular (2e-6 kg·m² on the turntable) to
    // well conditioned along the motion.
    c.push_back({"postures",
                 "prismatic near zero extension",
                 "a slider of 1 kg on a massless turntable spinning at 5 rad/s, 1 mm from the "
                 "axis: the turntable moves only the slider's 1e-6 kg·m² and 1e-6 kg·m² more",
                 m,
                 {0, 1e-3},
                 {5, 0},
                 1,
                 1e-3});
  }
  // Size and gravity.
  {
    StressCase s{"size",
                 "chain of 1000 links",
                 "random_tree plugin, 1000 bodies in one chain",
                 {{"model", "random_tree"},
                  {"params", {{"seed", 3}, {"bodies", quick ? 200 : 1000}, {"branching", 0}}}},
                 {},
                 {},
                 4e-3,
                 1e-3};
    if (quick)
      s.name = "chain of 200 links",
      s.description = "random_tree plugin, 200 bodies in one chain (--quick)";
    s.large = true;
    c.push_back(s);
  }
  c.push_back({"gravity",
               "zero gravity",
               "the finger in space",
               finger(0),
               {0.1, 0.5, 0.6, 0.5},
               {0.5, 1, 1, 1},
               0.5,
               1e-3});
  c.push_back({"gravity",
               "1000 g",
               "the finger at 9810 m/s²",
               finger(9810),
               {0.1, 0.5, 0.6, 0.5},
               {0.5, 1, 1, 1},
               0.01,
               1e-4});
  // A massless chain end: M^s singular, refused.
  c.push_back({"singular",
               "zero-mass chain end",
               "a 1 kg link with a massless link at its end",
               chain("massless end", {1, 0}, {0.5, 0.5}),
               {},
               {},
               0.5,
               1e-3});
  c.back().model["bodies"][1]["elements"] = Json::array();
  c.back().expect = "refused";
  loop_cases(c, quick);
  flexible_cases(c);
  for (auto& s : c)
    if (s.expect.empty()) s.expect = "stable";
  return c;
}

}  // namespace femdyn::cli
