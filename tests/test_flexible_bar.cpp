// The flexible bar (io/flexible_bar.hpp, docs/flexible.md): a cantilever's natural frequencies
// from femdyn's linearisation converge to beam theory's closed forms at order 2 in the number
// of segments, in both bending planes, torsion and stretch; the two ways of giving the section
// are one model; where the bar is clamped does not change its modes; the bar as the multibody
// chain it is matches Simbody; a curved bar rests on its arc and matches Simbody too; modal and
// Rayleigh damping give the modes their ratios; bad input is refused naming the key.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "core/derivatives/derivatives.hpp"
#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/equations.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/names.hpp"
#include "sim/stability.hpp"
#include "tests/helpers.hpp"
#include "tests/validation_checks.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A steel bar of 1 m, 1 mm square but with I_z = 2 I_y (so that the planes differ), clamped.
constexpr double kE = 2.1e11, kG = 8.1e10, kRho = 7850, kB = 1e-3, kL = 1;
constexpr double kA = kB * kB, kIy = kB * kB * kB * kB / 12, kIz = 2 * kIy, kJ = 2 * kIy;

std::string num(double x) { return format_number(x, "%.17g"); }

std::string section_e() {
  return R"({"E": )" + num(kE) + R"(, "G": )" + num(kG) + R"(, "density": )" + num(kRho) +
         R"(, "area": )" + num(kA) + R"(, "Iy": )" + num(kIy) + R"(, "Iz": )" + num(kIz) +
         R"(, "J": )" + num(kJ) + "}";
}

std::string cantilever(int segments, const std::string& section = section_e(),
                       const std::string& origin = "", const std::string& gravity = "[0, 0, 0]") {
  return R"({"name": "cantilever", "gravity": )" + gravity + R"(, "bodies": [],
    "flexible_bars": [{"name": "bar", "parent": "world", "length": )" +
         num(kL) + R"(, "segments": )" + std::to_string(segments) + R"(, "section": )" + section +
         origin + "}]}";
}

// The natural frequencies (rad/s, ascending) of the model linearised at rest.
std::vector<double> frequencies(const Model& m) {
  Workspace ws(m);
  const VecX z = VecX::Zero(m.n());
  const Linearization lin = linearize(m, ws, z, z, z);
  REQUIRE(lin.status.ok);
  std::vector<double> w;
  for (const auto& l : lin.eigenvalues)
    if (l.imag() > 0) w.push_back(l.imag());
  std::sort(w.begin(), w.end());
  return w;
}

double relative_error_to_nearest(const std::vector<double>& w, double exact) {
  double best = std::numeric_limits<double>::infinity();
  for (double x : w) best = std::min(best, std::abs(x - exact) / exact);
  return best;
}

// The cantilever's closed forms: bending (β_k L)² √(EI/(ρA L⁴)), torsion and stretch
// (2k − 1)π/(2L) √(GJ/(ρ I_p)) and √(E/ρ).
std::vector<double> exact_modes() {
  const double bl[] = {1.8751040687119611, 4.6940911329741745, 7.8547574382376126};
  std::vector<double> w;
  for (double I : {kIy, kIz})
    for (double b : bl) w.push_back(b * b * std::sqrt(kE * I / (kRho * kA * std::pow(kL, 4))));
  w.push_back(std::numbers::pi / (2 * kL) * std::sqrt(kG * kJ / (kRho * (kIy + kIz))));
  w.push_back(std::numbers::pi / (2 * kL) * std::sqrt(kE / kRho));
  return w;
}

// M^s, h and Q of a and b agree within tol at 3 random states (q in ±q_range, q̇ in ±qd_range).
void check_same_equations(const Model& a, const Model& b, double q_range, double qd_range,
                          double tol) {
  REQUIRE(a.n() == b.n());
  Workspace wa(a), wb(b);
  std::mt19937 rng(5);
  for (int k = 0; k < 3; ++k) {
    const VecX q = random_uniform(a.n(), q_range, rng), qd = random_uniform(a.n(), qd_range, rng);
    evaluate(a, wa, q, qd, VecX::Zero(a.n()));
    evaluate(b, wb, q, qd, VecX::Zero(b.n()));
    CHECK(rel_error(wb.Ms, wa.Ms) < tol);
    CHECK(rel_error(wb.h, wa.h) < tol);
    CHECK(rel_error(wb.Q, wa.Q) < tol);
  }
}

}  // namespace

TEST_CASE("a cantilever's modes converge to beam theory at order 2 in the segments", "[flexible]") {
  const std::vector<double> exact = exact_modes();  // 3 + 3 bending, torsion, stretch
  std::vector<double> previous;
  for (int n : {8, 16, 32}) {
    const Model m = load_text(cantilever(n));
    CHECK(m.n() == 4 * n);  // ry, rz, rx, ux at each joint
    const std::vector<double> w = frequencies(m);
    std::vector<double> errors;
    for (double x : exact) errors.push_back(relative_error_to_nearest(w, x));
    INFO("segments " << n);
    // The measured errors (docs/flexible.md): 8 segments 3.6e-3 (first bending) to 2.0e-2
    // (third), 1.6e-3 torsion and stretch; each a quarter of it at twice the segments.
    for (double e : errors) CHECK(e < 2.5e-2 * (8.0 / n) * (8.0 / n));
    if (!previous.empty())
      for (std::size_t k = 0; k < errors.size(); ++k) {
        INFO("mode " << k);
        const double order = std::log2(previous[k] / errors[k]);
        CHECK(order > 1.85);
        CHECK(order < 2.15);
      }
    previous = errors;
  }
}

TEST_CASE("a flexible bar given by E, G, ρ and the section is the bar given by its rigidities",
          "[flexible]") {
  const std::string rigidities = R"({"EA": )" + num(kE * kA) + R"(, "EIy": )" + num(kE * kIy) +
                                 R"(, "EIz": )" + num(kE * kIz) + R"(, "GJ": )" + num(kG * kJ) +
                                 R"(, "rhoA": )" + num(kRho * kA) + "}";
  const Model a = load_text(cantilever(6, section_e(), "", "[0.3, -1, -9.81]"));
  const Model b = load_text(cantilever(6, rigidities, "", "[0.3, -1, -9.81]"));
  REQUIRE(a.coordinate_names == b.coordinate_names);
  // (ρI = ρA EI/EA when not given: the homogeneous section's, the same up to round-off)
  check_same_equations(a, b, 0.05, 0.5, 1e-14);
}

TEST_CASE("a flexible bar's equations do not depend on where and how it is clamped", "[flexible]") {
  // Without gravity, the bar clamped 100 m away and turned is the same mechanism: its M^s, h
  // and Q at any state are the same (issue 43's bound, 1e-11 relative).
  const Model here = load_text(cantilever(6));
  const Model there = load_text(
      cantilever(6, section_e(), R"(, "origin": {"xyz": [100, -30, 7], "rpy": [0.3, -1.1, 2]})"));
  check_same_equations(here, there, 0.3, 2, 1e-11);
}

TEST_CASE("a flexible bar on a moving body matches Simbody", "[flexible][validation]") {
  // A hub turning about z carrying a bar with damping, under gravity: the chain of segments
  // and its springs and dampers is an ordinary multibody system for Simbody.
  const std::string text = R"({"name": "hub and bar", "gravity": [0, 0, -9.81], "bodies": [
    {"name": "hub", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "rigid_body", "mass": 2, "inertia": {"ixx": 0.1, "iyy": 0.1,
                   "izz": 0.2}}]}],
    "flexible_bars": [{"name": "arm", "parent": "hub", "length": 0.8, "segments": 3,
      "origin": {"xyz": [0.1, 0, 0], "rpy": [0, 0.2, 0]},
      "section": {"E": 7e10, "G": 2.6e10, "density": 2700, "area": 1e-4, "Iy": 2e-9,
                  "Iz": 3e-9, "J": 4e-9},
      "axial": false, "damping": {"stiffness_proportional": 1e-4}}]})";
  const Model m = load_text(text);
  // Pointwise (M^s, h, Q, q̈, τ at 8 states): the stiff springs make a trajectory of Simbody
  // take minutes. M^s, h, Q and τ within 1e-10; q̈ and the accelerations within M^s's condition
  // number times 1e-14, about 45 ε (each engine's solve errs by a few ε κ; light torsion next to
  // a heavy hub: κ ≈ 3e5 here, q̈ measured 8.7e-10).
  const validation::ValidationReport r = validation::validate(m, quick(8, 0));
  REQUIRE(r.failure.empty());
  Workspace ws(m);
  mass_matrix(m, ws, VecX::Zero(m.n()));
  const Eigen::SelfAdjointEigenSolver<MatX> eig(ws.Ms);
  const double kappa = eig.eigenvalues().maxCoeff() / eig.eigenvalues().minCoeff();
  CHECK(kappa > 1e4);  // (else the looser bound below is not needed)
  for (const auto& q : r.quantities) {
    INFO(q.name << " max rel error " << q.max_rel << ", κ(M^s) " << kappa);
    const bool solved =
        q.name.find("qdd") != std::string::npos || q.name.find("acceleration") != std::string::npos;
    CHECK(q.max_rel < (solved ? 1e-14 * kappa : 1e-10));
  }
}

// A curved bar (docs/flexible.md, "curvature"): its joints lie on the arc, the chords between
// them, each body's frame along the arc's tangent there; its mass is ρA L; nearly straight it
// is the straight bar; and as the multibody chain it is, it matches Simbody.
TEST_CASE("a curved flexible bar rests on its arc and matches Simbody", "[flexible][validation]") {
  const double radius = 0.5, kappa = 1 / radius;  // the 1 m bar turns by 2 rad
  const Vec3 axis = Vec3(0, 0.6, 0.8), normal = axis.cross(Vec3::UnitX());
  const std::string curved = R"(, "curvature": {"radius": 0.5, "axis": [0, 0.6, 0.8]})";
  const int n = 6;
  const Model m = load_text(cantilever(n, section_e(), curved));
  Workspace ws(m);
  const VecX z = VecX::Zero(m.n());
  propagate(m, ws, VecX::Zero(m.n_q()), z, {.jacobian = false, .bias = false, .rows = false});
  const auto body = [&](const std::string& name) {
    for (std::size_t b = 0; b < m.bodies.size(); ++b)
      if (m.bodies[b].name == name) return static_cast<int>(b);
    FAIL("no body " << name);
    return -1;
  };
  const auto on_arc = [&](double s) {  // the arc's point at arc length s from the clamp
    return Vec3(std::sin(kappa * s) / kappa * Vec3::UnitX() +
                (1 - std::cos(kappa * s)) / kappa * normal);
  };
  const double delta = kL / n;
  for (int i = 1; i <= n + 1; ++i) {
    const std::string name = i <= n ? "bar." + std::to_string(i) : "bar.tip";
    const double s = i <= n ? (i - 0.5) * delta : kL;
    const BodyState& B = ws.body[body(name)];
    CHECK((ws.origin + B.p - on_arc(s)).norm() < 1e-14);
    CHECK((B.R - axis_rotation(axis, kappa * s)).norm() < 1e-14);  // along the tangent
  }
  double mass = 0;
  for (const MassProperties& p : body_mass_properties(m)) mass += p.mass;
  CHECK(mass == Approx(kRho * kA * kL).epsilon(1e-14));
  // Nearly straight (R = 1e6 m): the straight bar's equations, to the curvature's first order.
  check_same_equations(load_text(cantilever(n)),
                       load_text(cantilever(n, section_e(), R"(, "curvature": {"radius": 1e6})")),
                       0.05, 1, 1e-5);
  // On a hub under gravity, against Simbody (as the straight bar above).
  const std::string text = R"({"name": "hub and curved bar", "gravity": [0, 0, -9.81],
    "bodies": [{"name": "hub", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "rigid_body", "mass": 2, "inertia": {"ixx": 0.1, "iyy": 0.1,
                   "izz": 0.2}}]}],
    "flexible_bars": [{"name": "arm", "parent": "hub", "length": 0.8, "segments": 3,
      "curvature": {"radius": 0.6, "axis": [0, 1, 0]},
      "section": {"E": 7e10, "G": 2.6e10, "density": 2700, "area": 1e-4, "Iy": 2e-9,
                  "Iz": 3e-9, "J": 4e-9}, "axial": false}]})";
  const validation::ValidationReport r = validation::validate(load_text(text), quick(8, 0));
  REQUIRE(r.failure.empty());
  for (const auto& q : r.quantities) {
    INFO(q.name << " max rel error " << q.max_rel);
    CHECK(q.max_rel < 1e-8);
  }
}

// The damping ratios of the cantilever's modes, ascending in frequency: ζ = −Re λ / |λ|.
std::vector<std::pair<double, double>> damped_modes(const Model& m) {
  Workspace ws(m);
  const VecX z = VecX::Zero(m.n());
  const Linearization lin = linearize(m, ws, z, z, z);
  REQUIRE(lin.status.ok);
  std::vector<std::pair<double, double>> out;  // (ω_n, ζ)
  for (const auto& l : lin.eigenvalues)
    if (l.imag() > 0) out.emplace_back(std::abs(l), -l.real() / std::abs(l));
  std::sort(out.begin(), out.end());
  return out;
}

// Modal damping gives each clamped mode its ratio; mass-proportional α adds α/(2ω), beside the
// stiffness-proportional β's βω/2 (Rayleigh). The derivatives carry −D, the Simbody twin the same
// force, and the damping dissipates: its power −q̇ᵀ D q̇ is in the energy balance.
TEST_CASE("a flexible bar's modal and Rayleigh damping give the modes their ratios",
          "[flexible][validation]") {
  const int n = 6;
  const auto with = [&](const std::string& damping) {
    return load_text(cantilever(n, section_e(), R"(, "damping": )" + damping));
  };
  const std::vector<std::pair<double, double>> modal =
      damped_modes(with(R"({"modal": [0.01, 0.02, 0.05]})"));
  REQUIRE(modal.size() == 4 * n);
  for (std::size_t k = 0; k < modal.size(); ++k)
    CHECK(modal[k].second == Approx(k == 0 ? 0.01 : k == 1 ? 0.02 : 0.05).margin(1e-9));
  const double alpha = 3, beta = 1e-6;
  const std::vector<std::pair<double, double>> rayleigh =
      damped_modes(with(R"({"mass_proportional": 3, "stiffness_proportional": 1e-6})"));
  const std::vector<double> undamped = frequencies(load_text(cantilever(n)));
  REQUIRE(rayleigh.size() == undamped.size());
  for (std::size_t k = 0; k < rayleigh.size(); ++k) {
    const double w = undamped[k];
    CHECK(rayleigh[k].second == Approx(alpha / (2 * w) + beta * w / 2).epsilon(1e-7));
  }
  // ∂q̈/∂q̇ against central differences, at a state in motion (without the damping it is not
  // the same matrix: the check can fail).
  const Model m = with(R"({"modal": 0.03, "mass_proportional": 0.5})");
  REQUIRE(m.has_rate_damping);
  Workspace ws(m);
  DerivativeWorkspace d(m);
  std::mt19937 rng(3);
  const VecX q = random_posture(m, rng), qd = random_rates(m, 1.0, rng), tau = VecX::Zero(m.n());
  REQUIRE(forward_dynamics_derivatives(m, ws, d, q, qd, tau).ok);
  MatX fd(m.n(), m.n());
  for (int j = 0; j < m.n(); ++j) {
    const double h = 0.1;  // (q̈ is quadratic in q̇: central differences are exact but for round-off)
    VecX a = qd, b = qd;
    a[j] += h;
    b[j] -= h;
    REQUIRE(forward_dynamics(m, ws, q, a, tau).ok);
    const VecX qa = ws.qdd;
    REQUIRE(forward_dynamics(m, ws, q, b, tau).ok);
    fd.col(j) = (qa - ws.qdd) / (2 * h);
  }
  CHECK(rel_error(fd, d.dqdd_dv) < 1e-6);
  // Simbody applies the same −D θ̇: Q and q̈ agree pointwise.
  const validation::ValidationReport r = validation::validate(m, quick(6, 0));
  REQUIRE(r.failure.empty());
  for (const auto& x : r.quantities) {
    INFO(x.name << " max rel error " << x.max_rel);
    CHECK(x.max_rel < 1e-8);
  }
}

TEST_CASE("a flexible bar's bad input is refused in one line naming the key", "[flexible]") {
  CHECK_THAT(text_error(cantilever(4, section_e(), R"(, "damping": {"modal": []})")),
             Catch::Contains("/flexible_bars/0/damping/modal: expected a damping ratio"));
  CHECK_THAT(text_error(cantilever(4, section_e(), R"(, "damping": {"modal": [0.1, -1]})")),
             Catch::Contains("/flexible_bars/0/damping/modal: ratio 1 must be at least 0"));
  CHECK_THAT(text_error(cantilever(4, section_e(), R"(, "curvature": {"radius": -1})")),
             Catch::Contains("/flexible_bars/0/curvature/radius: must be positive"));
  CHECK_THAT(text_error(cantilever(4, section_e(), R"(, "curvature": {"radius": 1,
      "axis": [1, 0, 0]})")),
             Catch::Contains("/flexible_bars/0/curvature/axis: expected a direction across"));
  CHECK_THAT(text_error(cantilever(0)),
             Catch::Contains("/flexible_bars/0/segments: expected an integer from 1 to"));
  CHECK_THAT(text_error(cantilever(4, R"({"EIy": 1, "EIz": 1, "rhoA": 1, "GJ": 1})")),
             Catch::Contains("/flexible_bars/0/section/EA: ") && Catch::Contains("missing"));
  CHECK_THAT(text_error(cantilever(4, R"({"E": 1, "density": 1, "area": 1, "Iy": 1, "Iz": -1,
      "G": 1, "J": 1})")),
             Catch::Contains("/flexible_bars/0/section/Iz: must be positive"));
  CHECK_THAT(text_error(cantilever(4, section_e(), R"(, "stiffness": 3)")),
             Catch::Contains("/flexible_bars/0/stiffness: unknown key"));
  // A name the bar's bodies would repeat is refused, naming the bar.
  CHECK_THAT(text_error(R"({"name": "twice", "bodies": [
      {"name": "bar.0", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}],
      "flexible_bars": [{"name": "bar", "parent": "world", "length": 1, "segments": 2,
       "section": )" + section_e() +
                        "}]}"),
             Catch::Contains("/flexible_bars/0") && Catch::Contains("bar.0"));
}

TEST_CASE("random states keep a flexible bar at small strains (sample_range)", "[flexible]") {
  // 0.05 rad a part in bending and torsion, a stretch of 1e-3 of a part: the random postures
  // and rates of check, stress and validate stay there; a joint's own sample_range likewise.
  const Model m = load_text(cantilever(4));
  std::mt19937 rng(3);
  const double delta = kL / 4;
  for (int k = 0; k < 20; ++k) {
    const VecX q = random_posture(m, rng), v = random_rates(m, 1.0, rng);
    for (int i = 0; i < m.n(); ++i) {
      const bool stretch = m.coordinate_names[i].ends_with(".ux");
      const double range = stretch ? 1e-3 * delta : 0.05;
      CHECK(std::abs(q[i]) <= range);
      CHECK(std::abs(v[i]) <= range / (stretch ? 0.5 : std::numbers::pi));
    }
  }
  const Model own = load_text(R"({"name": "r", "bodies": [{"name": "a", "parent": "world",
    "joint": {"type": "revolute", "axis": [0, 0, 1], "sample_range": 0.2},
    "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}]})");
  for (int k = 0; k < 20; ++k) CHECK(std::abs(random_posture(own, rng)[0]) <= 0.2);
  CHECK_THAT(text_error(R"({"name": "r", "bodies": [{"name": "a", "parent": "world",
    "joint": {"type": "spherical", "sample_range": 0.2},
    "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}]})"),
             Catch::Contains("/bodies/0/joint/sample_range: is the half range of a joint of one "
                             "coordinate"));
  CHECK_THAT(text_error(R"({"name": "r", "bodies": [{"name": "a", "parent": "world",
    "joint": {"type": "revolute", "axis": [0, 0, 1], "sample_range": -1},
    "elements": [{"type": "lumped_point", "node": [1, 0, 0], "mass": 1}]}]})"),
             Catch::Contains("/bodies/0/joint/sample_range: must be positive"));
}

TEST_CASE("a spinning cantilever stiffens as the rotating-beam references say", "[flexible]") {
  // Geometric (centrifugal) stiffening: a cantilever on a hub turning at Ω about an axis
  // normal to it. Its first flapwise frequency, in units of √(EI/(ρA L⁴)), at Ω = λ in the same
  // units (Hodges & Rutkowski, AIAA J. 19(11), 1981, table 1; Wright et al. 1982): it rises from
  // 3.516 to 11.2 at λ = 10. femdyn's is the linearisation about the steady spin, whose
  // stiffening comes from the exact kinematics (no term is added for it); it converges to these
  // at order 2, as the modes at rest do.
  const double reference[] = {3.5160, 3.6817, 4.1373, 4.7973,  5.5850, 6.4495,
                              7.3604, 8.2996, 9.2568, 10.2257, 11.2023};
  const double unit = std::sqrt(kE * kIy / (kRho * kA * std::pow(kL, 4)));
  std::vector<double> previous;
  for (int n : {16, 32}) {
    const Model m = load_text(R"({"name": "spinning", "bodies": [
      {"name": "hub", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
       "elements": [{"type": "rigid_body", "mass": 1, "inertia": {"ixx": 1, "iyy": 1,
                     "izz": 1}}]}],
      "flexible_bars": [{"name": "bar", "parent": "hub", "length": 1, "segments": )" +
                              std::to_string(n) + R"(, "axial": false, "torsion": false,
        "section": {"E": 2.1e11, "density": 7850, "area": 1e-6, "Iy": 8.333333333333333e-14,
                    "Iz": 3.333333333333333e-13}}]})");
    Workspace ws(m);
    std::vector<double> errors;
    for (int lambda = 0; lambda <= 10; ++lambda) {
      VecX qd = VecX::Zero(m.n());
      qd[0] = lambda * unit;  // the hub's rate; the straight bar is a steady spin
      const Linearization lin = linearize(m, ws, VecX::Zero(m.n()), qd, VecX::Zero(m.n()));
      REQUIRE(lin.status.ok);
      std::vector<double> w;
      for (const auto& l : lin.eigenvalues)
        if (l.imag() > 0) w.push_back(l.imag() / unit);
      const double e = relative_error_to_nearest(w, reference[lambda]);
      INFO("n = " << n << ", λ = " << lambda);
      CHECK(e < 3e-3 * (16.0 / n) * (16.0 / n));  // measured 9e-4 to 2.9e-3 at n = 16
      errors.push_back(e);
    }
    if (!previous.empty())
      for (int lambda = 1; lambda <= 10; ++lambda) {
        INFO("λ = " << lambda);
        CHECK(previous[lambda] / errors[lambda] > 3.5);  // order 2: a quarter
      }
    previous = errors;
  }
}

TEST_CASE("linearize's frequencies are the modal analysis' ω² = eig(K, M^s)", "[flexible]") {
  // At rest without gravity the bar's stiffness is its springs alone, K = diag(EI_y/Δ, EI_z/Δ,
  // GJ/Δ, EA/Δ) per joint: the generalized symmetric eigenproblem K x = ω² M^s x, solved apart,
  // must give the frequencies linearize's A does.
  const int n = 6;
  const Model m = load_text(cantilever(n));
  const double delta = kL / n;
  VecX k(m.n());
  for (int i = 0; i < m.n(); ++i) {
    const std::string& c = m.coordinate_names[i];
    const std::string rate = c.substr(c.rfind('.') + 1);
    k[i] = (rate == "ry"   ? kE * kIy
            : rate == "rz" ? kE * kIz
            : rate == "rx" ? kG * kJ
                           : kE * kA) /
           delta;
  }
  Workspace ws(m);
  mass_matrix(m, ws, VecX::Zero(m.n()));
  const MatX K = k.asDiagonal();
  const Eigen::GeneralizedSelfAdjointEigenSolver<MatX> modal(K, ws.Ms);
  const std::vector<double> w = frequencies(m);
  REQUIRE(static_cast<int>(w.size()) == m.n());
  for (int i = 0; i < m.n(); ++i) {
    INFO("mode " << i);
    CHECK(std::abs(w[i] / std::sqrt(modal.eigenvalues()[i]) - 1) < 1e-6);
  }
}

TEST_CASE("a flexible bar at rest moves its hub as the rigid bar of the same section",
          "[flexible]") {
  // With the elastic coordinates at 0 and still, the pieces make up the whole uniform bar: the
  // hub's M^s entry, its velocity terms and gravity's Q equal those of a rigid space bar with
  // the same density, area and second moments (elements/space_bar.hpp).
  const std::string hub = R"({"name": "hub", "parent": "world", "joint": {"type": "revolute",
      "axis": [0.2, 1, 0.3]}, "elements": [{"type": "lumped_point", "node": [0, 0, 0.1],
      "mass": 1}]})";
  const Model flexible = load_text(R"({"name": "flexible", "gravity": [0.3, -1, -9.81],
    "bodies": [)" + hub + R"(], "flexible_bars": [{"name": "bar", "parent": "hub",
    "length": 1, "segments": 5, "section": )" +
                                   section_e() + "}]}");
  const Model rigid = load_text(R"({"name": "rigid", "gravity": [0.3, -1, -9.81], "bodies": [)" +
                                hub + R"(, {"name": "bar", "parent": "hub", "joint": {"type":
      "fixed"}, "elements": [{"type": "space_bar", "nodes": [[0, 0, 0], [1, 0, 0]],
      "density": )" + num(kRho) +
                                R"(, "area": )" + num(kA) + R"(, "Iy": )" + num(kIy) +
                                R"(, "Iz": )" + num(kIz) + "}]}]}");
  Workspace wf(flexible), wr(rigid);
  for (const double angle : {0.0, 0.7, -2.0}) {
    VecX qf = VecX::Zero(flexible.n()), qdf = VecX::Zero(flexible.n());
    qf[0] = angle, qdf[0] = 1.3;
    const VecX qr = qf.head(1), qdr = qdf.head(1);
    evaluate(flexible, wf, qf, qdf, VecX::Zero(flexible.n()));
    evaluate(rigid, wr, qr, qdr, VecX::Zero(1));
    INFO("hub at " << angle);
    CHECK(std::abs(wf.Ms(0, 0) / wr.Ms(0, 0) - 1) < 1e-13);
    CHECK(std::abs(wf.Q[0] - wr.Q[0]) < 1e-13 * std::abs(wr.Q[0]) + 1e-15);
    CHECK(std::abs(wf.h[0] - wr.h[0]) < 1e-13 * (std::abs(wr.Ms(0, 0)) + 1));
  }
}
