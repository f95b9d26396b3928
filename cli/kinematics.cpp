// femdyn kinematics: the pose, Jacobian, velocity and J̇v of named frames at a state
// (core/kinematics/frames.hpp), the centre of mass and the centroidal momentum
// (core/kinematics/momentum.hpp), and on a free-floating tree each frame's generalized Jacobian —
// what a controller asks of the model.
#include "core/kinematics/kinematics.hpp"

#include <iostream>
#include <sstream>

#include "cli/commands.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/momentum.hpp"
#include "core/model/errors.hpp"
#include "core/model/names.hpp"
#include "core/workspace/memory.hpp"
#include "io/output.hpp"

namespace femdyn::cli {
namespace {

constexpr const char* kKinematicsHelp =
    R"(usage: femdyn kinematics MODEL [--q …] [--qd …] [--frame NAME[,NAME…]]
                          [--axes local_world_aligned|local|world] [--json] [--gravity gx,gy,gz]
                          [--max-memory GB]

The kinematics of frames at the state (--q: n_q values, default the neutral configuration, on a
model with closed loops assembled onto them as simulate starts; --qd: n rates, default 0): each
frame's position p and orientation R (world), its Jacobian J (6 × n, linear rows then angular),
its velocity J v and J̇v, the acceleration at q̈ = 0, in the chosen axes (docs/notation.md#frames):
  local_world_aligned (default)  about the frame's origin, world axes
  local                          about the frame's origin, the frame's own axes
  world                          the body point at the world origin, world axes (spatial)
Frames: every body by its name, and the model's named "frames"; without --frame, the named
frames, or the bodies without children when it has none.

The mechanism as a whole (docs/notation.md#momentum): its mass m, centre of mass c, the Jacobian
J_c (ċ = J_c v) and c̈ at q̈ = 0; its centroidal momentum h_G = (P, L_G) (linear, then angular
about c, world axes), the centroidal momentum matrix A_G (h_G = A_G v) and Ȧ_G v. On a tree
on a free joint, each frame's generalized Jacobian J* (Umetani–Yoshida): its velocity is
J* v_m + drift with the base floating, v_m the rates of every joint but the base's.

--json prints {"model", "n", "coordinates", "axes", "q", "qd", "frames": [{"name", "body", "p",
"R", "J", "velocity", "bias"[, "generalized_jacobian": {"rates", "J", "drift"}]}],
"centroidal": {"mass", "com", "Jcom", "com_velocity", "com_bias", "inertia_com", "momentum",
"A", "bias"}}.
Each frame's Jacobians grow as n: beyond the memory limit (--max-memory GB, default half the
available memory) the command is refused before any work, with the memory it would need.
)";

// The frames asked for, by name; by default the named frames, else the leaf bodies.
std::vector<int> chosen_frames(const Args& a, const Model& m) {
  std::vector<int> out;
  if (a.has("frame")) {
    std::istringstream names(a.options.at("frame"));
    for (std::string name; std::getline(names, name, ',');) {
      const int f = find_frame(m, name);
      if (f < 0) {
        std::string known;
        for (const Frame& F : m.frames) known += (known.empty() ? "" : ", ") + F.name;
        throw CliError("--frame: no frame " + quoted_text(name) + " (frames: " + known + ")");
      }
      out.push_back(f);
    }
    return out;
  }
  for (std::size_t f = m.bodies.size(); f < m.frames.size(); ++f)
    out.push_back(static_cast<int>(f));
  if (!out.empty()) return out;
  std::vector<bool> parent(m.bodies.size(), false);
  for (const Body& b : m.bodies)
    if (b.parent >= 0) parent[b.parent] = true;
  for (std::size_t b = 0; b < m.bodies.size(); ++b)
    if (!parent[b]) out.push_back(static_cast<int>(b));
  return out;
}

// Whether the model is one tree on a free joint (core/kinematics/momentum.hpp): then J* is printed.
bool floating_tree(const Model& m) {
  try {
    floating_base_rate(m);
    return true;
  } catch (const ModelError&) {
    return false;
  }
}

// One frame's kinematics as JSON and as text; with a floating base, its generalized Jacobian.
Json frame_entry(const Model& m, int f, const FrameKinematics& k, const MomentumKinematics& c,
                 bool floating, std::ostream& text) {
  const std::string body = m.bodies[m.frames[f].body].name;
  Json entry = {{"name", m.frames[f].name},   {"body", body},
                {"p", vector_json(k.p)},      {"R", matrix_json(k.R)},
                {"J", matrix_json(k.J)},      {"velocity", vector_json(k.velocity)},
                {"bias", vector_json(k.bias)}};
  text << "\nframe " << m.frames[f].name << " (body " << body << ")\n  p = " << k.p.transpose()
       << "\n  R =\n"
       << k.R << "\n  J (linear rows, then angular) =\n"
       << k.J << "\n  velocity (v, w) = " << k.velocity.transpose()
       << "\n  Jdot v (q'' = 0)  = " << k.bias.transpose() << "\n";
  if (floating) {
    GeneralizedJacobian g;
    generalized_jacobian(m, k, c, g);
    std::vector<std::string> rates;
    for (const int r : g.rates) rates.push_back(m.coordinate_names[r]);
    entry["generalized_jacobian"] = {
        {"rates", rates}, {"J", matrix_json(g.J)}, {"drift", vector_json(g.drift)}};
    text << "  generalized Jacobian J* (base floating; columns: every rate after the base's) =\n"
         << g.J << "\n  drift J_b A_b^-1 h = " << g.drift.transpose() << "\n";
  }
  return entry;
}

// The mechanism's centre of mass and centroidal momentum as JSON, and as text.
Json centroidal_entry(const MomentumKinematics& c, std::ostream& text) {
  text << "\nmechanism: mass " << c.mass << " kg\n  com c = " << c.com.transpose() << "\n  J_c =\n"
       << c.Jcom << "\n  com velocity = " << c.com_velocity.transpose()
       << "\n  com acceleration at q'' = 0 = " << c.com_bias.transpose()
       << "\n  centroidal momentum h_G (P, L_G) = " << c.momentum.transpose() << "\n  A_G =\n"
       << c.A << "\n  A_G-dot v (q'' = 0) = " << c.bias.transpose() << "\n";
  return {{"mass", c.mass},
          {"com", vector_json(c.com)},
          {"Jcom", matrix_json(c.Jcom)},
          {"com_velocity", vector_json(c.com_velocity)},
          {"com_bias", vector_json(c.com_bias)},
          {"inertia_com", matrix_json(c.inertia_com)},
          {"momentum", vector_json(c.momentum)},
          {"A", matrix_json(c.A)},
          {"bias", vector_json(c.bias)}};
}

}  // namespace

int cmd_kinematics(int argc, char** argv) {
  const Args a = parse_args(argc, argv, 2, {"help", "json"},
                            {"q", "qd", "frame", "axes", "gravity", "max-memory"});
  if (a.has("help")) {
    std::cout << kKinematicsHelp;
    return 0;
  }
  const Model m = load(a);
  FrameAxes axes = FrameAxes::LocalWorldAligned;
  if (a.has("axes") && !parse_frame_axes(a.options.at("axes"), axes))
    throw CliError("--axes expects local_world_aligned, local or world");
  const auto [q, qd, tau] = command_state(a, m);
  const std::vector<int> frames = chosen_frames(a, m);
  // At most: the workspace, and per frame its Jacobians (J and the generalized one, 12n numbers
  // with p, R and the rest), the momentum's (A_G, J_c: 9n), held and printed.
  const double n = m.n(), numbers = frames.size() * (12 * n + 30) + 9 * n + 30;
  require_command_memory(a,
                         "the kinematics of " + std::to_string(frames.size()) +
                             " frames of n = " + std::to_string(m.n()) + " coordinates",
                         evaluation_bytes(m) + 8 * numbers + printed_bytes(numbers, a.has("json")));
  Workspace ws(m);
  FrameKinematics k;
  Json list = Json::array();
  std::ostringstream text;
  text << "model: " << m.name << "\naxes: " << frame_axes_name(axes) << "\n";
  propagate(m, ws, q, qd, {.jacobian = true, .bias = true, .rows = false});
  MomentumKinematics c;
  momentum_kinematics(m, ws, c);
  if (!c.A.allFinite() || !c.bias.allFinite()) throw CliError(overflow_text("the momentum"));
  const bool floating = floating_tree(m);
  for (const int f : frames) {
    frame_kinematics(m, ws, f, axes, k);
    if (!k.J.allFinite() || !k.bias.allFinite() || !k.p.allFinite())
      throw CliError(
          overflow_text("the kinematics of frame " + quoted_text(m.frames[f].name), true));
    list.push_back(frame_entry(m, f, k, c, floating, text));
  }
  const Json centroidal = centroidal_entry(c, text);
  if (a.has("json"))
    std::cout << json_text(Json{{"model", m.name},
                                {"n", m.n()},
                                {"coordinates", m.coordinate_names},
                                {"axes", frame_axes_name(axes)},
                                {"q", vector_json(q)},
                                {"qd", vector_json(qd)},
                                {"frames", list},
                                {"centroidal", centroidal}})
              << "\n";
  else
    std::cout << text.str();
  return 0;
}

}  // namespace femdyn::cli
