// One truth (docs/robustness.md#one-truth): the same physics asked another way gives the same
// answer. Metamorphic relations on seeded random mechanisms of every kind (every joint type,
// linear and nonlinear couplings, rods, springs, loads, floating bases, closed loops) and on the
// bundled models:
//   - placement: the whole mechanism moved by a rigid motion (R, t) — its roots, the places it
//     has on the world, its loads and gravity with it — keeps M^s, h, Q, q̈, τ and ∂q̈ (the
//     coordinates are relative: a free joint's in its joint frame), on every route, at |t| up to
//     1e6 m;
//   - splitting: each body split into two welded ones (its mass shared between them, its
//     children moved to the second) keeps the same answers;
//   - the entry points: a state of the wrong size is refused by the C++ API in one line;
//   - the doors: `femdyn equations --json` gives the C++ API's numbers, closed loops included.
// FEMDYN_RELATION_SCALE=k (default 1) runs k times as many random mechanisms: the nightly-size
// run of docs/robustness.md.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <random>

#include "core/derivatives/derivatives.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/frames.hpp"
#include "core/loops/assembly.hpp"
#include "core/model/arguments.hpp"
#include "io/params.hpp"
#include "models/model_files.hpp"
#include "models/random_tree.hpp"
#include "tests/helpers.hpp"
#include "tests/loop_checks.hpp"

namespace femdyn::test {
namespace {

// The number of random mechanisms a relation runs: `n` times FEMDYN_RELATION_SCALE (default 1).
int relation_count(int n) {
  const char* text = std::getenv("FEMDYN_RELATION_SCALE");
  const int scale = text ? std::atoi(text) : 1;
  return n * std::max(1, scale);
}

// R = Rz(y) Ry(p) Rx(r) back to (r, p, y) (rpy_to_rotation's inverse away from p = ±π/2).
Vec3 rpy_of(const Mat3& R) {
  return {std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
          std::atan2(R(1, 0), R(0, 0))};
}

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

struct Placement {
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();
};

void place_frame(const Placement& P, Vec3& xyz, Vec3& rpy) {
  xyz = P.R * xyz + P.t;
  if (!P.R.isIdentity(0)) rpy = rpy_of(P.R * rpy_to_rotation(rpy));
}

void place_attachment(const Placement& P, AttachmentSpec& a) {
  if (a.frame == "world") a.frame.clear(), a.body = "world";  // the world's own frame
  if (a.frame.empty() && a.body == "world") place_frame(P, a.xyz, a.rpy);
}

// The spec moved as a whole by P: every joint on the world, every place on the world, the loads'
// world-axes forces and torques, and gravity.
MechanismSpec placed(MechanismSpec s, const Placement& P) {
  for (BodySpec& b : s.bodies)
    if (b.parent == "world") place_frame(P, b.joint.xyz, b.joint.rpy);
  for (LoadSpec& l : s.loads) l.force = P.R * l.force, l.torque = P.R * l.torque;
  for (ConstraintSpec& c : s.constraints) place_attachment(P, c.a), place_attachment(P, c.b);
  for (SpringSpec& c : s.springs) place_attachment(P, c.a), place_attachment(P, c.b);
  s.gravity = P.R * s.gravity;
  return s;
}

// Whether nothing but one root body is placed on the world (then the whole answer is independent
// of the world's numbers, rounding of the far position included).
bool one_place_on_world(const MechanismSpec& s) {
  int roots = 0;
  for (const BodySpec& b : s.bodies) roots += b.parent == "world";
  const auto on_world = [](const AttachmentSpec& a) {
    return a.frame == "world" || (a.frame.empty() && a.body == "world");
  };
  for (const ConstraintSpec& c : s.constraints)
    if (c.type != "gear" && (on_world(c.a) || on_world(c.b))) return false;
  for (const SpringSpec& c : s.springs)
    if (on_world(c.a) || on_world(c.b)) return false;
  return roots == 1;
}

// What a model answers at a state: M^s, h, Q, q̈ (the mechanism's), τ(q̈), ∂q̈/∂q, ∂q̈/∂v and a
// frame's J and velocity in its own axes.
struct Answers {
  MatX M, dq, dv, J;
  VecX h, Q, qdd, tau, velocity;
  std::string failure;
  int redundant = 0;  // loop equations that repeat others at the state (rows − rank)
  double condition = 1;  // cond(M^s), times cond(S) (S = Φ_q M⁻¹ Φ_qᵀ, over its rank) with loops
};

Answers answers(const Model& m, const VecX& q, const VecX& v, const VecX& tau) {
  Answers a;
  Workspace ws(m);
  std::unique_ptr<LoopWorkspace> loops =
      m.constraints.empty() ? nullptr : std::make_unique<LoopWorkspace>(m);
  const Status st = mechanism_forward_dynamics(m, ws, loops.get(), q, v, tau);
  if (!st.ok) {
    a.failure = st.message;
    return a;
  }
  a.qdd = ws.qdd;
  if (loops) {
    a.redundant = m.constraint_rows - loops->rank;
    const VecX sigma = Eigen::JacobiSVD<MatX>(loops->S).singularValues();
    a.condition = sigma[0] / sigma[std::max(0, loops->rank - 1)];
  }
  evaluate(m, ws, q, v, tau);
  a.M = ws.Ms, a.h = ws.h, a.Q = ws.Q;
  const VecX sigma_M = Eigen::JacobiSVD<MatX>(a.M).singularValues();
  a.condition *= sigma_M[0] / sigma_M[sigma_M.size() - 1];
  if (m.constraints.empty()) {
    inverse_dynamics(m, ws, q, v, a.qdd);
    a.tau = ws.tau;
  }
  if (derivatives_unsupported(m).empty()) {
    DerivativeWorkspace d(m);
    d.baumgarte = 0;
    if (forward_dynamics_derivatives(m, ws, d, q, v, tau).ok) a.dq = d.dqdd_dq, a.dv = d.dqdd_dv;
  }
  FrameKinematics k;
  frame_kinematics(m, ws, q, v, static_cast<int>(m.frames.size()) - 1, FrameAxes::Local, k);
  a.J = k.J, a.velocity = k.velocity;
  return a;
}

// The largest of |a − b|∞ / scale over the answers, and which answer it is. The scale is that of
// the quantity's kind, so that an entry that is zero in one and round-off in the other counts as
// round-off: the forces h, Q, τ share max(|h|, |Q|, |τ|), the derivatives ∂q̈/∂q and ∂q̈/∂v
// share theirs, the frame's velocity has max(|J q̇|, |J| |q̇|).
struct Change {
  double value = 0;
  std::string what;
};
std::ostream& operator<<(std::ostream& out, const Change& c) {
  return out << c.value << " (" << c.what << ")";
}

double largest(std::initializer_list<const MatX*> xs) {
  double s = 0;
  for (const MatX* x : xs)
    if (x->size()) s = std::max(s, x->cwiseAbs().maxCoeff());
  return s;
}

Change worst_change(const Answers& a, const Answers& b, double v_max) {
  Change worst;
  const auto take = [&](const char* what, const MatX& x, const MatX& y, double scale) {
    double change = x.size() == y.size() ? 0.0 : INFINITY;
    if (x.size() && x.size() == y.size())
      change = (x - y).cwiseAbs().maxCoeff() / std::max(scale, 1e-300);
    if (change > worst.value || std::isnan(change)) worst = {change, what};
  };
  const MatX h = b.h, Q = b.Q, tau = b.tau, dq = b.dq, dv = b.dv, qdd = b.qdd, vel = b.velocity;
  const double forces = largest({&h, &Q, &tau}), derivatives = largest({&dq, &dv});
  take("M^s", a.M, b.M, largest({&b.M}));
  take("h", a.h, b.h, forces), take("Q", a.Q, b.Q, forces), take("tau", a.tau, b.tau, forces);
  take("qdd", a.qdd, b.qdd, largest({&qdd}));
  take("dqdd/dq", a.dq, b.dq, derivatives), take("dqdd/dv", a.dv, b.dv, derivatives);
  take("J", a.J, b.J, largest({&b.J}));
  take("J qd", a.velocity, b.velocity, std::max(largest({&vel}), largest({&b.J}) * v_max));
  return worst;
}

// A state of the model: random posture and rates; with loops assembled onto them.
bool random_state(const Model& m, std::mt19937& rng, VecX& q, VecX& v, VecX& tau) {
  q = random_posture(m, rng), v = random_uniform(m.n(), 1.0, rng);
  tau = random_uniform(m.n(), 0.5, rng);
  if (m.constraints.empty()) return true;
  q = neutral_posture(m);
  q = integrate_posture(m, q, random_uniform(m.n(), 0.05, rng));
  return assemble_state(m, q, v).assembly.status.ok;
}

struct Case {
  std::string name;
  MechanismSpec spec;
};

std::vector<Case> mechanisms_of_every_kind(int per_kind) {
  std::vector<Case> out;
  const auto add = [&](const std::string& name, const std::string& text) {
    out.push_back({name, parse_spec(text, name)});
  };
  for (int s = 1; s <= per_kind; ++s) {
    const auto seed = static_cast<unsigned>(s);
    // (Couplings join joints of one rate: the helper adds them to trees without the others.)
    add("mixed tree " + std::to_string(s), mixed_tree_json(seed, 7, 0.4, false, true));
    add("coupled tree " + std::to_string(s), mixed_tree_json(seed, 7, 0.4, true, false));
    add("tree " + std::to_string(s), random_tree_json(seed, 6, 0.5, true));
    int rods = 0;
    add("rods " + std::to_string(s), with_rods(mixed_tree_json(seed, 6, 0.4, false), seed, rods));
    add("nonlinear couplings " + std::to_string(s), nonlinear_coupled_tree_json(seed));
    add("closed loops " + std::to_string(s), closable_tree(seed, s % 2 == 0));
  }
  return out;
}

void check_placements(const Case& c, std::mt19937& rng, const RouteChoice& routes) {
  const Model m0 = compile(c.spec, {.routes = routes});
  VecX q, v, tau;
  if (!random_state(m0, rng, q, v, tau)) return;  // (a loop that does not close there)
  const Answers a0 = answers(m0, q, v, tau);
  if (!a0.failure.empty()) return;  // (a singular state: no answer to compare)
  const Mat3 R = Eigen::Quaterniond::UnitRandom().toRotationMatrix();  // (Eigen's rand())
  const Vec3 dir = random_uniform(3, 1.0, rng).normalized();
  // Turned at the origin: the same answers to round-off.
  const MechanismSpec turned = placed(c.spec, {R, Vec3::Zero()});
  const Answers ar = answers(compile(turned, {.routes = routes}), q, v, tau);
  const double v_max = v.cwiseAbs().maxCoeff();
  // Turning is no relation where the model fixes something in world axes (an explicit
  // correlation table keeps or leaves out world-axis translations: the paper's finger). With
  // redundant loop equations the rank decision at 1e-10 of S's largest pivot moves with
  // round-off, q̈ by up to about that much, and ∂q̈/∂q off the loops is not unique (each choice
  // of the independent rows differentiates another way): q̈ to 1e-7, ∂q̈ left out.
  if (!m0.explicit_table) {
    Answers a = ar, b = a0;
    if (a0.redundant > 0)
      for (Answers* x : {&a, &b}) x->dq.resize(0, 0), x->dv.resize(0, 0);
    const Change turned_change = worst_change(a, b, v_max);
    // Round-off alone moves q̈ by up to about cond ε (cond(M^s), times cond(S) with loops: the
    // 81-link chain of the N four-bar); the relation holds to that, and to 1e-11 where it is
    // smaller (every random mechanism).
    const double tolerance =
        a0.redundant > 0 ? 1e-7 : std::max(1e-11, 10 * kEpsilon * a0.condition);
    INFO(c.name << ": turned: " << ar.failure << " change " << turned_change << ", redundant "
                << a0.redundant << ", condition " << a0.condition);
    CHECK(turned_change.value < tolerance);
  }
  for (const double distance : {1e3, 1e6}) {
    const Vec3 t = distance * dir;
    // Far away, and back: the same relative geometry, rounded once at the far place.
    const MechanismSpec far = placed(turned, {Mat3::Identity(), t});
    const MechanismSpec back = placed(far, {Mat3::Identity(), -t});
    const Answers af = answers(compile(far, {.routes = routes}), q, v, tau),
                  ab = answers(compile(back, {.routes = routes}), q, v, tau);
    const Change back_change = worst_change(af, ab, v_max),
                 turned_far = worst_change(af, ar, v_max);
    INFO(c.name << " at " << distance << " m: " << af.failure << " / " << ab.failure
                << "; change from back " << back_change << ", from turned " << turned_far);
    CHECK(back_change.value < 1e-11);
    // With one place on the world, the far mechanism is exactly the turned one.
    if (one_place_on_world(c.spec)) CHECK(turned_far.value < 1e-11);
  }
}

}  // namespace

TEST_CASE("moving the whole mechanism (1e3 m, 1e6 m, turned) changes no answer, on every route",
          "[one-truth][placement]") {
  std::mt19937 rng(43);
  std::srand(43);  // (Eigen's random rotations)
  const std::vector<RouteChoice> routes = main_routes();
  int checked = 0;
  for (const Case& c : mechanisms_of_every_kind(relation_count(6)))
    for (const RouteChoice& r : routes) {
      INFO(c.name);
      if (r.mass || r.force || r.dynamics) {
        try {
          (void)compile(c.spec, {.routes = r});
        } catch (const ModelError&) {
          continue;  // a body-level route asked where it is not exact
        }
      }
      check_placements(c, rng, r);
      ++checked;
    }
  CHECK(checked >= 60);  // (36 mechanisms, each on its own routes and those that apply)
}

TEST_CASE("the bundled models far from the origin: M^s, h, Q, q̈, τ and ∂q̈ unchanged",
          "[one-truth][placement]") {
  std::mt19937 rng(7);
  std::srand(7);
  for (const std::string& file : bundled_models()) {
    const Case c{file, read_spec(model_path(file))};
    check_placements(c, rng, {});
  }
}

namespace {

// The spec with its bodies listed in another order (a body may come before its parent) and
// renamed "renamed_<name>" everywhere they are named (parents, loads, frames, the ends of loops
// and springs, the nodes of elements that span bodies); joints keep their names, so the
// coordinates keep theirs.
MechanismSpec reordered_and_renamed(MechanismSpec s, std::mt19937& rng) {
  std::map<std::string, std::string> to;
  for (BodySpec& b : s.bodies) {
    if (b.joint.name.empty()) b.joint.name = b.name;  // (a joint is named after its body)
    to[b.name] = "renamed_" + b.name;
  }
  const auto rename = [&](std::string& name) {
    if (const auto it = to.find(name); it != to.end()) name = it->second;
  };
  const auto rename_label = [&](std::string& label) {
    if (const std::size_t cut = label.find('/'); cut != std::string::npos) {
      std::string body = label.substr(0, cut);
      rename(body);
      label = body + label.substr(cut);
    }
  };
  for (BodySpec& b : s.bodies) {
    rename(b.name), rename(b.parent);
    for (ElementSpec& e : b.elements)
      for (std::string& label : e.node_labels) rename_label(label);
  }
  for (LoadSpec& l : s.loads) rename(l.body);
  for (FrameSpec& f : s.frames) rename(f.body);
  for (ConstraintSpec& c : s.constraints)
    rename(c.a.body), rename(c.a.frame), rename(c.b.body), rename(c.b.frame);
  for (SpringSpec& c : s.springs)
    rename(c.a.body), rename(c.a.frame), rename(c.b.body), rename(c.b.frame);
  std::shuffle(s.bodies.begin(), s.bodies.end(), rng);
  return s;
}

// x of model `from` in the coordinate order of model `to` (by the coordinates' names); rows and
// columns of a matrix alike.
std::vector<int> coordinate_map(const Model& from, const Model& to) {
  std::vector<int> at(to.n());
  for (int i = 0; i < to.n(); ++i) {
    const auto it = std::find(from.coordinate_names.begin(), from.coordinate_names.end(),
                              to.coordinate_names[i]);
    at[i] = static_cast<int>(it - from.coordinate_names.begin());
  }
  return at;
}

}  // namespace

TEST_CASE("listing the bodies in another order and renaming them changes no answer",
          "[one-truth][naming]") {
  std::mt19937 rng(47);
  int compared = 0;
  for (const Case& c : mechanisms_of_every_kind(relation_count(4))) {
    const Model a = compile(c.spec);
    const Model b = compile(reordered_and_renamed(c.spec, rng));
    REQUIRE(b.n() == a.n());
    const std::vector<int> at = coordinate_map(b, a);  // b's index of a's coordinate i
    VecX q, v, tau;
    if (!a.constraints.empty() || !flat_model(a)) continue;  // (q's layout: flat trees only)
    if (!random_state(a, rng, q, v, tau)) continue;
    VecX qb(b.n()), vb(b.n()), taub(b.n());
    for (int i = 0; i < a.n(); ++i) qb[at[i]] = q[i], vb[at[i]] = v[i], taub[at[i]] = tau[i];
    const Answers x = answers(a, q, v, tau), y = answers(b, qb, vb, taub);
    REQUIRE(x.failure.empty());
    REQUIRE(y.failure.empty());
    Answers y_in_a = x;  // b's answers in a's order (the frame compared is each model's last)
    for (int i = 0; i < a.n(); ++i) {
      y_in_a.qdd[i] = y.qdd[at[i]], y_in_a.h[i] = y.h[at[i]], y_in_a.Q[i] = y.Q[at[i]];
      y_in_a.tau[i] = y.tau[at[i]];
      for (int k = 0; k < a.n(); ++k) y_in_a.M(i, k) = y.M(at[i], at[k]);
    }
    y_in_a.dq.resize(0, 0), y_in_a.dv.resize(0, 0), y_in_a.J.resize(0, 0);
    y_in_a.velocity.resize(0);
    Answers x_cut = x;
    x_cut.dq.resize(0, 0), x_cut.dv.resize(0, 0), x_cut.J.resize(0, 0), x_cut.velocity.resize(0);
    const Change change = worst_change(y_in_a, x_cut, v.cwiseAbs().maxCoeff());
    INFO(c.name << ": " << change);
    CHECK(change.value < 1e-12 * std::max(1.0, x.condition * 1e-4));
    ++compared;
  }
  CHECK(compared >= 8);
}

namespace {

using Json = nlohmann::json;

Vec3 vec3_of(const Json& a) { return {a[0].get<double>(), a[1].get<double>(), a[2].get<double>()}; }
Json json_of(const Vec3& x) { return Json::array({x[0], x[1], x[2]}); }
Json json_of(const Mat3& I) {
  return Json::array({json_of(Vec3(I.row(0))), json_of(Vec3(I.row(1))), json_of(Vec3(I.row(2)))});
}
Mat3 inertia_of(const Json& e) {  // {"ixx", …} or a 3 × 3 array
  const Json& i = e["inertia"];
  if (i.is_array()) {
    Mat3 I;
    for (int r = 0; r < 3; ++r) I.row(r) = vec3_of(i[r]).transpose();
    return I;
  }
  const auto at = [&](const char* k) { return i.contains(k) ? i[k].get<double>() : 0.0; };
  Mat3 I;
  I << at("ixx"), at("ixy"), at("ixz"), at("ixy"), at("iyy"), at("iyz"), at("ixz"), at("iyz"),
      at("izz");
  return I;
}
Mat3 parallel_axis(const Vec3& r, double m) {  // m (|r|² 1 − r rᵀ)
  return m * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
}

// The mechanism with each body B split in two welded ones: a new body B_w on a fixed joint at a
// random (t, R) in B carries B's point masses, rotary nodes and 60 % of its rigid body (the
// other 40 % stays, the two parts' centres of mass 2 cm apart, their inertias set so that the
// union is B's), its children hang from B_w (their joint frames carried over), and B keeps its
// space bars and loads. The same mechanism: the same coordinates, M^s, h, Q, q̈, τ.
std::string welded_split(const std::string& text, std::mt19937& rng) {
  Json doc = Json::parse(text);
  std::uniform_real_distribution<double> u(-1, 1);
  const auto random3 = [&](double s) {  // (in order: a constructor's arguments are unsequenced)
    const double x = u(rng), y = u(rng), z = u(rng);
    return Vec3(s * x, s * y, s * z);
  };
  Json out = Json::array();
  std::map<std::string, std::pair<Vec3, Mat3>> welded;  // body -> (t, R) of its B_w
  for (const Json& b : doc["bodies"]) {
    const Vec3 t = random3(0.3);
    const Mat3 R = rpy_to_rotation(random3(2.0));
    const auto to_w = [&](const Vec3& x) { return Vec3(R.transpose() * (x - t)); };
    Json body = b, part = {{"name", b["name"].get<std::string>() + "_w"},
                           {"parent", b["name"]},
                           {"joint",
                            {{"name", b["name"].get<std::string>() + "_weld"},
                             {"type", "fixed"},
                             {"origin", {{"xyz", json_of(t)}, {"rpy", rpy_of(R)}}}}},
                           {"elements", Json::array()}};
    body["elements"] = Json::array();
    for (const Json& e : b["elements"]) {
      const std::string type = e["type"];
      Json moved = e;
      if (type == "lumped_point" || type == "rotary_node") {
        moved["node"] = json_of(to_w(vec3_of(e["node"])));
        if (type == "rotary_node")
          moved["inertia"] = json_of(Mat3(R.transpose() * inertia_of(e) * R));
        part["elements"].push_back(moved);
      } else if (type == "rigid_body") {  // 40 % at c + 0.6 d, 60 % at c − 0.4 d
        const double m = e["mass"], alpha = 0.4;
        const Vec3 c = vec3_of(e["com"]), d = random3(0.02);
        const Vec3 c1 = c + (1 - alpha) * d, c2 = c - alpha * d;
        const Mat3 rest = inertia_of(e) - parallel_axis(c1 - c, alpha * m) -
                          parallel_axis(c2 - c, (1 - alpha) * m);
        Json kept = e;
        kept["mass"] = alpha * m, kept["com"] = json_of(c1),
        kept["inertia"] = json_of(Mat3(alpha * rest));
        moved["mass"] = (1 - alpha) * m, moved["com"] = json_of(to_w(c2));
        moved["inertia"] = json_of(Mat3((1 - alpha) * R.transpose() * rest * R));
        body["elements"].push_back(kept);
        part["elements"].push_back(moved);
      } else {
        body["elements"].push_back(e);
      }
    }
    welded[b["name"]] = {t, R};
    out.push_back(body);
    out.push_back(part);
  }
  for (Json& b : out) {  // children of B onto B_w: their joint frames seen from B_w
    const auto it = welded.find(b["parent"].get<std::string>());
    if (it == welded.end() || b["name"] == it->first + "_w") continue;
    const auto& [t, R] = it->second;
    Json& origin = b["joint"]["origin"];
    const Vec3 xyz = origin.contains("xyz") ? vec3_of(origin["xyz"]) : Vec3::Zero();
    const Vec3 rpy = origin.contains("rpy") ? vec3_of(origin["rpy"]) : Vec3::Zero();
    origin["xyz"] = json_of(Vec3(R.transpose() * (xyz - t)));
    origin["rpy"] = json_of(rpy_of(R.transpose() * rpy_to_rotation(rpy)));
    b["parent"] = it->first + "_w";
  }
  doc["bodies"] = out;
  return doc.dump();
}

}  // namespace

TEST_CASE("splitting each body into two welded ones changes no answer", "[one-truth][welded]") {
  std::mt19937 rng(53);
  int compared = 0;
  Change worst;
  const int seeds = relation_count(6);
  for (unsigned seed = 1; seed <= static_cast<unsigned>(seeds); ++seed) {
    const Json tree_params = {{"seed", seed}, {"bodies", 6}, {"branching", 0.5}};
    const std::string kinds[] = {mixed_tree_json(seed, 7, 0.4, false, true),
                                 mixed_tree_json(seed, 7, 0.4, true, false),
                                 random_tree(Params(tree_params, "random_tree: ")).dump()};
    for (const std::string& text : kinds) {
      const Model a = load_text(text), b = load_text(welded_split(text, rng));
      REQUIRE(b.bodies.size() == 2 * a.bodies.size());
      REQUIRE(b.configuration_names == a.configuration_names);
      REQUIRE(b.coordinate_names == a.coordinate_names);
      VecX q, v, tau;
      REQUIRE(random_state(a, rng, q, v, tau));
      const Answers x = answers(a, q, v, tau), y = answers(b, q, v, tau);
      REQUIRE(x.failure.empty());
      REQUIRE(y.failure.empty());
      Answers x_cut = x, y_cut = y;  // (the frame compared is each model's last: not the same)
      for (Answers* w : {&x_cut, &y_cut}) w->J.resize(0, 0), w->velocity.resize(0);
      const Change change = worst_change(y_cut, x_cut, v.cwiseAbs().maxCoeff());
      INFO(a.name << ": " << change << ", cond " << x.condition);
      CHECK(change.value < std::max(1e-11, 100 * kEpsilon * x.condition));
      if (change.value > worst.value) worst = change;
      ++compared;
    }
  }
  CHECK(compared == 3 * seeds);
  WARN("welded split: worst change " << worst);
}

TEST_CASE("a free base flown 1 km and 1000 km away (its own q) changes no answer",
          "[one-truth][placement]") {
  // The space robot, and random trees on a free joint: the base's x, y, z in q moved far.
  std::vector<Model> models;
  models.push_back(load_model(model_path("space_robot.json")));
  for (unsigned seed : {1u, 3u, 5u})
    models.push_back(load_text(mixed_tree_json(seed, 7, 0.4, false, true)));
  std::mt19937 rng(11);
  for (const Model& m : models) {
    if (m.bodies[0].joint.type != JointType::Free) continue;
    VecX q, v, tau;
    REQUIRE(random_state(m, rng, q, v, tau));
    const Answers near = answers(m, q, v, tau);
    REQUIRE(near.failure.empty());
    for (const double distance : {1e3, 1e6}) {
      VecX q_far = q;
      q_far.head<3>() += distance * Vec3(0.6, -0.8, 0.0);
      const Change change = worst_change(answers(m, q_far, v, tau), near, v.cwiseAbs().maxCoeff());
      INFO(m.name << " at " << distance << " m: " << change);
      CHECK(change.value < 1e-11);
    }
  }
}

TEST_CASE("a spherical pendulum's q̈ keeps its closed form 1e6 m from the origin",
          "[one-truth][placement]") {
  // A 2 kg point 0.7 m out on a ball joint with a rotary inertia of 0.01 kg m² about every
  // axis, at rest, gravity along −z: ω̇ = (0, m g l / (m l² + 0.01), 0); far away the same.
  for (const double far : {0.0, 1.0, 1e3, 1e6}) {
    char text[1024];
    std::snprintf(text, sizeof text, R"({"name": "spherical", "gravity": [0, 0, -9.81], "bodies": [
      {"name": "bob", "parent": "world",
       "joint": {"name": "ball", "type": "spherical", "origin": {"xyz": [%.17g, %.17g, 0]}},
       "nodes": {"tip": [0.7, 0, 0]},
       "elements": [{"type": "lumped_point", "node": "tip", "mass": 2},
                    {"type": "rotary_node", "node": "tip",
                     "inertia": {"ixx": 0.01, "iyy": 0.01, "izz": 0.01}}]}]})",
                  far, -0.5 * far);
    const Model m = load_text(text);
    Workspace ws(m);
    const VecX q = neutral_posture(m);
    REQUIRE(forward_dynamics(m, ws, q, VecX::Zero(3), VecX()).ok);
    VecX expected = VecX::Zero(3);
    expected[1] = 2 * 9.81 * 0.7 / (2 * 0.7 * 0.7 + 0.01);
    INFO("pivot " << far << " m out");
    CHECK(rel_error(ws.qdd, expected) < 1e-13);
  }
}

TEST_CASE("the C++ entry points refuse a state of the wrong size in one line naming it",
          "[one-truth][arguments]") {
  const Model m = load_model(model_path("space_robot.json"));
  Workspace ws(m);
  const VecX q = neutral_posture(m), v = VecX::Zero(m.n());
  REQUIRE(m.n_q() == m.n() + 1);
  const auto message = [](const auto& call) -> std::string {
    try {
      call();
    } catch (const ArgumentError& e) {
      return e.what();
    }
    return "(accepted)";
  };
  CHECK(message([&] { mass_matrix(m, ws, v); }) ==
        "mass_matrix: q has 33 entries; the model 'space robot' has n_q = 34 configuration "
        "coordinates");
  CHECK_THAT(message([&] { (void)forward_dynamics(m, ws, q, v, VecX::Zero(3)); }),
             Catch::StartsWith("forward_dynamics: tau has 3 entries"));
  CHECK_THAT(message([&] { evaluate_bias(m, ws, q, VecX::Zero(m.n_q())); }),
             Catch::StartsWith("evaluate_bias: qd has 34 entries"));
  CHECK_THAT(message([&] { inverse_dynamics(m, ws, q, v, VecX::Zero(2)); }),
             Catch::StartsWith("inverse_dynamics: qdd has 2 entries"));
  CHECK_THAT(message([&] { (void)energy(m, ws, v, v); }), Catch::StartsWith("energy: q has 33"));
  DerivativeWorkspace d(m);
  CHECK_THAT(message([&] { (void)forward_dynamics_derivatives(m, ws, d, v, v, VecX()); }),
             Catch::StartsWith("forward_dynamics_derivatives: q has 33"));
  // No actuation at all is τ = 0, as before, with springs too (core/dynamics/springs.hpp; the model
  // has loops: its spanning tree).
  CHECK(message([&] { (void)forward_dynamics(m, ws, q, v, VecX()); }) == "(accepted)");
  const Model sprung = load_text(every_constraint_tree(5));
  REQUIRE(!sprung.springs.empty());
  Workspace w1(sprung), w2(sprung);
  std::mt19937 rng(5);
  const VecX qs = random_posture(sprung, rng), vs = random_uniform(sprung.n(), 1, rng);
  REQUIRE(tree_forward_dynamics(sprung, w1, qs, vs, VecX()).ok);
  REQUIRE(tree_forward_dynamics(sprung, w2, qs, vs, VecX::Zero(sprung.n())).ok);
  CHECK(w1.qdd == w2.qdd);
}

TEST_CASE(
    "femdyn equations on closed loops: the constrained q̈ and λ, and a state off the "
    "loops refused",
    "[one-truth][loops][cli]") {
  Scratch dir("one_truth_loops");
  const std::string text = closable_tree(3, false), file = dir / "closed.json";
  std::ofstream(file) << text;
  const Model m = load_text(text);
  // Without --q: the neutral configuration assembled, and q̈ of the closed mechanism.
  const Run r = run("equations " + file + " --json");
  REQUIRE(r.code == 0);
  const Json j = Json::parse(r.out);
  const VecX q = Eigen::Map<const VecX>(j["q"].get<std::vector<double>>().data(), m.n_q());
  const VecX qdd = Eigen::Map<const VecX>(j["qdd"].get<std::vector<double>>().data(), m.n());
  CHECK(check_constrained_equations(m, q, VecX::Zero(m.n()), VecX::Zero(m.n())) >= 0);
  Workspace ws(m);
  LoopWorkspace lws(m);
  REQUIRE(constrained_forward_dynamics(m, ws, lws, q, VecX::Zero(m.n()), VecX(), 0).ok);
  CHECK(rel_error(qdd, ws.qdd) < 1e-9);  // (the JSON's printed digits)
  CHECK(j["lambda"].size() == static_cast<std::size_t>(m.constraint_rows));
  // The open tree's q̈ is not the answer: the tip is held. The C++ API's forward_dynamics
  // refuses the model in one line rather than give it; tree_forward_dynamics gives it by name.
  try {
    (void)forward_dynamics(m, ws, q, VecX::Zero(m.n()), VecX());
    FAIL("forward_dynamics accepted a model with closed loops");
  } catch (const ArgumentError& e) {
    CHECK_THAT(std::string(e.what()),
               Catch::StartsWith("forward_dynamics: the model '" + m.name + "' has closed loops (" +
                                 std::to_string(m.constraint_rows) + " constraint equations)") &&
                   Catch::Contains("mechanism_forward_dynamics"));
  }
  REQUIRE(tree_forward_dynamics(m, ws, q, VecX::Zero(m.n()), VecX()).ok);
  CHECK(rel_error(qdd, ws.qdd) > 1e-3);
  VecX tree_qdd = ws.qdd;
  evaluate(m, ws, q, VecX::Zero(m.n()), VecX::Zero(m.n()));
  CHECK(rel_error(tree_qdd, VecX(ws.Ms.ldlt().solve(ws.Q - ws.h))) < 1e-10);
  // A --q that does not close the loops: exit 1, one line naming the constraint.
  std::string zeros;
  for (int i = 0; i < m.n_q(); ++i) zeros += (i ? "," : "") + std::string("0.3");
  const Run off = run("equations " + file + " --q " + zeros);
  CHECK(off.code == 1);
  CHECK_THAT(off.out,
             Catch::Contains("does not close the loops") && Catch::Contains("at constraint '"));
}

TEST_CASE("smaller seams: info counts joints as joints, loops that cannot close exit 1, not 2",
          "[one-truth][cli]") {
  const Model robot = load_model(model_path("space_robot.json"));
  const Run info = run("info " + model_path("space_robot.json"));
  REQUIRE(info.code == 0);
  int movable = 0;
  for (const Body& b : robot.bodies) movable += moves(b.joint);
  CHECK_THAT(info.out, Catch::Contains("joints (" + std::to_string(robot.bodies.size()) + ", " +
                                       std::to_string(movable) + " movable, " +
                                       std::to_string(robot.n_theta()) + " joint rates)"));
  CHECK(movable < robot.n_theta());  // (the free base: one joint, six rates)
  // A ball 2 m from a 1 m arm's reach: a state error (exit 1), not a command-line one (2).
  Scratch dir("one_truth_far");
  const std::string file = dir / "far.json";
  std::ofstream(file) << R"({"name": "far", "gravity": [0, -9.81, 0], "bodies": [
    {"name": "l", "parent": "world", "joint": {"name": "a", "type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "rigid_body", "mass": 1, "com": [0.5, 0, 0],
                   "inertia": {"ixx": 0.01, "iyy": 0.1, "izz": 0.1}}]}],
    "constraints": [{"name": "pin", "type": "ball", "a": {"body": "l", "xyz": [1, 0, 0]},
                     "b": {"body": "world", "xyz": [3, 0, 0]}, "normal": [0, 0, 1]}]})";
  for (const std::string& command :
       {"simulate " + file + " --t-end 0.1", "linearize " + file, "equations " + file}) {
    const Run r = run(command);
    INFO(command << ": " << r.out);
    CHECK(r.code == 1);
    CHECK_THAT(r.out, Catch::Contains("cannot close"));
  }
}

TEST_CASE("femdyn track refuses what computed torque would ignore: loops, a free base",
          "[one-truth][cli]") {
  Scratch dir("one_truth_track");
  const std::string file = dir / "closed.json";
  std::ofstream(file) << closable_tree(3, false);
  const Run loops = run("track " + file + " --to 0,0,0,0,0,0,0,0,0,0 2>&1");
  CHECK(loops.code == 1);
  CHECK_THAT(loops.out, Catch::Contains("closed loops"));
  const Run free = run("track " + model_path("space_robot.json") + " --to 0 2>&1");
  CHECK(free.code == 1);
  CHECK_THAT(free.out, Catch::Contains("free joint") && Catch::Contains("--actuated-base"));
}

}  // namespace femdyn::test

using namespace femdyn;  // (what follows is outside femdyn::test; a unity build must not lend it)
using namespace femdyn::test;

namespace {

std::string cli_numbers(const VecX& x) {
  std::string s;
  char buffer[32];
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    std::snprintf(buffer, sizeof buffer, "%.17g", x[i]);
    s += (i ? "," : "") + std::string(buffer);
  }
  return s;
}

MatX json_matrix(const Json& j) {
  MatX M(j.size(), j.empty() ? 0 : j[0].size());
  for (std::size_t r = 0; r < j.size(); ++r)
    for (std::size_t c = 0; c < j[r].size(); ++c) M(r, c) = j[r][c].get<double>();
  return M;
}

VecX json_vector(const Json& j) {
  VecX x(j.size());
  for (std::size_t i = 0; i < j.size(); ++i) x[i] = j[i].get<double>();
  return x;
}

}  // namespace

TEST_CASE("femdyn equations --json gives the C++ API's numbers bit for bit on random mechanisms",
          "[one-truth][cli]") {
  // Random mechanisms of every kind (trees of every joint type, couplings, rods, nonlinear laws,
  // closed loops), written to a file and read back by the command at a random state given at
  // round-trip precision (its quaternions normalised, as both the CLI and Python do): M^s, h, Q
  // and the mechanism's q̈ are the same doubles.
  Scratch dir("one_truth_cli_random");
  std::mt19937 rng(7);
  int compared = 0;
  for (int s = 1; s <= relation_count(2); ++s) {
    const auto seed = static_cast<unsigned>(s);
    int rods = 0;
    for (const std::string& text :
         {mixed_tree_json(seed, 7, 0.4, false, true), mixed_tree_json(seed, 7, 0.4, true, false),
          random_tree_json(seed, 6, 0.5, true),
          with_rods(mixed_tree_json(seed, 6, 0.4, false), seed, rods),
          nonlinear_coupled_tree_json(seed), closable_tree(seed, s % 2 == 0)}) {
      const std::string file = (dir.dir / ("m" + std::to_string(compared) + ".json")).string();
      std::ofstream(file) << text;
      const Model m = load_model(file);
      VecX q, v, tau;
      if (!random_state(m, rng, q, v, tau)) continue;
      REQUIRE(normalize_quaternions(m, q).empty());  // as the doors do with what they read
      const Answers a = answers(m, q, v, tau);
      if (!a.failure.empty()) continue;
      const Run r = run("equations " + file + " --q " + cli_numbers(q) + " --qd " + cli_numbers(v) +
                        " --tau " + cli_numbers(tau) + " --json 2>/dev/null");
      INFO(m.name << ": " << r.out.substr(0, 300));
      REQUIRE(r.code == 0);
      const Json j = Json::parse(r.out);
      INFO("M change " << rel_error(json_matrix(j["M"]), a.M) << ", q̈ change "
                       << rel_error(json_vector(j["qdd"]), a.qdd));
      CHECK(json_matrix(j["M"]) == a.M);
      CHECK(json_vector(j["h"]) == a.h);
      CHECK(json_vector(j["Q"]) == a.Q);
      CHECK(json_vector(j["qdd"]) == a.qdd);
      ++compared;
    }
  }
  CHECK(compared >= 10);
}
