#include "sim/stability.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>

#include "core/derivatives/derivatives.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/loops/constraint_kinematics.hpp"
#include "sim/motion.hpp"
#include "sim/step_stability.hpp"

namespace femdyn {
namespace {

// The oscillators x″ = k x + d ẋ that semi-implicit Euler sees (its step is not a map of the
// first-order modes one by one): one per pair of modes of A, k = −λ1 λ2 and d = λ1 + λ2 —
// a complex pair λ, λ̄, or two real modes of the same shape (the q parts of their eigenvectors
// parallel: the overdamped pair of a spring with ζ > 1, a saddle ±a). Mirrored as the modes
// are: k = −|λ1 λ2|, d = −|Re(λ1 + λ2)|. A real mode with no partner is first order: k = 0,
// d = −|λ|.
std::vector<Oscillator> euler_oscillators(const Linearization& lin) {
  const Eigen::EigenSolver<MatX> eig(lin.A, true);
  const Eigen::VectorXcd& ev = eig.eigenvalues();
  const Eigen::MatrixXcd V = eig.eigenvectors();  // (built anew by every call: once here)
  const Eigen::Index m = ev.size(), n = m / 2;
  std::vector<bool> used(m, false);
  std::vector<Oscillator> out;
  const auto add = [&](std::complex<double> a, std::complex<double> b) {
    out.push_back({-std::abs((a * b).real()), -std::abs((a + b).real())});
  };
  for (Eigen::Index i = 0; i < m; ++i) {
    if (used[i]) continue;
    used[i] = true;
    const double r = std::abs(ev[i]);
    if (std::abs(ev[i].imag()) > 1e-9 * r) {  // complex: its conjugate is its partner
      Eigen::Index j = -1;
      for (Eigen::Index c = 0; c < m; ++c)
        if (!used[c] &&
            (j < 0 || std::abs(ev[c] - std::conj(ev[i])) < std::abs(ev[j] - std::conj(ev[i]))))
          j = c;
      if (j >= 0) used[j] = true;
      add(ev[i], std::conj(ev[i]));
      continue;
    }
    // Real: the unused real mode whose shape is most nearly the same.
    // (copied: an `auto` Block of the temporary Block V.col(i) would dangle)
    const Eigen::VectorXcd shape_i = V.col(i).head(n);
    Eigen::Index j = -1;
    double best = 0.999;
    for (Eigen::Index c = 0; c < m; ++c) {
      if (used[c] || std::abs(ev[c].imag()) > 1e-9 * std::abs(ev[c])) continue;
      const Eigen::VectorXcd shape_c = V.col(c).head(n);
      const double nc = shape_c.norm() * shape_i.norm();
      const double cos = nc > 0 ? std::abs(shape_c.dot(shape_i)) / nc : 0;
      if (cos > best) best = cos, j = c;
    }
    if (j >= 0) {
      used[j] = true;
      add(ev[i], ev[j]);
    } else {
      out.push_back({0, -r});
    }
  }
  return out;
}

}  // namespace

double MassMatrixHealth::digits_lost() const {
  return std::isfinite(condition) ? std::log10(condition) : std::numeric_limits<double>::infinity();
}

MassMatrixHealth mass_matrix_health(const MatX& Ms) {
  MassMatrixHealth h;
  const double scale = Ms.cwiseAbs().maxCoeff();
  h.asymmetry = scale > 0 ? (Ms - Ms.transpose()).cwiseAbs().maxCoeff() / scale : 0;
  const Eigen::SelfAdjointEigenSolver<MatX> eig(Ms, Eigen::EigenvaluesOnly);
  h.lambda_min = eig.eigenvalues().minCoeff();
  h.lambda_max = eig.eigenvalues().maxCoeff();
  h.positive_definite = h.lambda_min > 0;
  h.condition =
      h.positive_definite ? h.lambda_max / h.lambda_min : std::numeric_limits<double>::infinity();
  return h;
}

double dead_point_ratio(const Model& m, const VecX& q, int rank) {
  if (m.constraints.empty() || rank <= 0) return std::numeric_limits<double>::infinity();
  Workspace ws(m);
  ConstraintKinematics k(m);
  constraint_kinematics(m, ws, q, VecX::Zero(m.n()), k);
  const Eigen::JacobiSVD<MatX> svd(k.J);
  const VecX& sigma = svd.singularValues();
  rank = std::min(rank, static_cast<int>(sigma.size()));
  return sigma[0] > 0 ? sigma[rank - 1] / sigma[0] : std::numeric_limits<double>::infinity();
}

namespace {

// A's eigenvalues, the stiffest and the largest growth rate; a NaN or Inf in A a failed Status.
void analyse(Linearization& lin) {
  if (!lin.A.allFinite()) {  // (an eigensolver given NaN may never return)
    lin.status = {false,
                  "the linearised dynamics are NaN or Inf at this state (the state or the "
                  "forces overflow double precision)",
                  -1, true};
    return;
  }
  lin.eigenvalues = Eigen::EigenSolver<MatX>(lin.A, false).eigenvalues();
  for (Eigen::Index i = 0; i < lin.eigenvalues.size(); ++i) {
    if (std::abs(lin.eigenvalues[i]) > std::abs(lin.stiffest)) lin.stiffest = lin.eigenvalues[i];
    lin.max_growth = std::max(lin.max_growth, lin.eigenvalues[i].real());
  }
}

}  // namespace

// A = [[∂ξ̇/∂ξ, 1], [∂q̈/∂q, ∂q̈/∂v]] from the analytic derivatives (docs/derivatives.md): one
// pass of the derivative recursion instead of 4n evaluations of forward dynamics.
Linearization linearize(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau, double baumgarte) {
  if (!derivatives_unsupported(m).empty())
    return difference_linearization(m, ws, q, qd, tau, baumgarte);
  Linearization lin;
  DerivativeWorkspace d(m);
  d.baumgarte = baumgarte;  // (closed loops: the constrained q̈ at this rate)
  MatX B;                   // (femdyn linearize's A and B: the same function)
  lin.status = linearize_state(m, ws, d, q, qd, tau, lin.A, B);
  if (!lin.status.ok) return lin;
  analyse(lin);
  return lin;
}

Linearization difference_linearization(const Model& m, Workspace& ws, const VecX& q, const VecX& qd,
                                       const VecX& tau, double baumgarte) {
  const int n = m.n();
  Linearization lin;
  lin.A = MatX::Zero(2 * n, 2 * n);
  lin.A.topRightCorner(n, n).setIdentity();
  VecX qp = q, qdp = qd, plus(n);
  // Closed loops: q̈ of the constrained equations at Baumgarte's rate (a run integrates them at
  // the default rate, whose pair of eigenvalues −ω is then among the modes).
  std::unique_ptr<LoopWorkspace> loops;
  if (!m.constraints.empty()) loops = std::make_unique<LoopWorkspace>(m);
  // Column j of [K D] by central differences: (q̈(y + δ e_j) − q̈(y − δ e_j)) / 2δ. With a
  // spherical or free joint y = (ξ, v) in the chart around q (sim/motion.hpp): q moves by
  // q ⊕ δ e_j, and the top rows are ∂ξ̇/∂(ξ, v) = [∂ξ̇/∂ξ, 1] at ξ = 0.
  const bool flat = flat_model(m);
  for (int j = 0; j < 2 * n; ++j) {
    VecX& x = j < n ? qp : qdp;
    const int i = j % n;
    const double x0 = x[i], delta = 1e-6 * std::max(1.0, flat || j >= n ? std::abs(x0) : 0.0);
    for (int side : {1, -1}) {
      if (flat || j >= n)
        x[i] = x0 + side * delta;
      else
        qp = integrate_posture(m, q, VecX::Unit(n, i) * (side * delta));
      lin.status = loops ? constrained_forward_dynamics(m, ws, *loops, qp, qdp, tau, baumgarte)
                         : tree_forward_dynamics(m, ws, qp, qdp, tau);
      if (!lin.status.ok) return lin;
      if (side == 1)
        plus = ws.qdd;
      else
        lin.A.block(n, j, n, 1) = (plus - ws.qdd) / (2 * delta);
    }
    if (flat || j >= n)
      x[i] = x0;
    else
      qp = q;
  }
  lin.A.topLeftCorner(n, n) = chart_rate_jacobian(m, qd);  // each joint type's ∂ξ̇/∂ξ
  analyse(lin);
  return lin;
}

std::optional<double> largest_stable_step(const Linearization& lin, IntegratorKind kind) {
  return with_step_stability(kind, [&]<class S>(S) -> std::optional<double> {
    if (!S::bounded) return std::numeric_limits<double>::infinity();
    const double rate = std::abs(lin.stiffest);
    if (!std::isfinite(rate) || !lin.status.ok) return std::nullopt;
    if (rate == 0) return std::numeric_limits<double>::infinity();
    const std::vector<Oscillator> oscillators =
        S::needs_oscillators ? euler_oscillators(lin) : std::vector<Oscillator>{};
    const ModeSet modes{lin.eigenvalues, oscillators};
    // Every explicit method here is unstable beyond h |λ| = 10; bisect on log h below that.
    double lo = 1e-6 / rate, hi = 10 / rate;
    if (!S::stable(modes, lo)) return 0.0;
    if (S::stable(modes, hi)) return hi;
    // (lo √(hi/lo), not √(lo hi): the product underflows for rates beyond 1e150; at most 60
    // halvings of log(hi/lo) = log 1e7 reach 1e-6)
    for (int i = 0; i < 60 && hi / lo > 1 + 1e-6; ++i) {
      const double mid = lo * std::sqrt(hi / lo);
      (S::stable(modes, mid) ? lo : hi) = mid;
    }
    return lo;
  });
}

bool has_dampers(const Model& m) {
  for (const Body& b : m.bodies)
    if (dissipates(b.joint)) return true;
  return false;
}

std::string Mode::text() const {
  const std::string w = format_short(omega) + " rad/s";
  switch (kind) {
    case ModeKind::None:
      return "no dynamics";
    case ModeKind::Oscillatory:
      if (!std::isnan(zeta)) return "oscillatory at " + w + ", damping ratio " + format_short(zeta);
      if (std::abs(lambda.real()) > 1e-6 * omega)
        return "oscillatory at " + w + "; its real part " + format_short(lambda.real()) +
               " 1/s comes from linearising at this state (not an equilibrium), not from damping";
      return "oscillatory at " + w + ", undamped";
    case ModeKind::Saddle:
      return "saddle: an unstable equilibrium, falling away at " + format_short(omega) + " 1/s";
    case ModeKind::Decaying:
      return "real, decaying: overdamped, time constant " + format_short(1 / omega) + " s";
    case ModeKind::Growing:
      return "real, growing at " + format_short(omega) + " 1/s: a fall, or the motion pulling away";
  }
  return "?";
}

std::vector<Mode> modes(const Linearization& lin, bool dissipative_model) {
  if (!lin.status.ok || lin.A.size() == 0 || !lin.A.allFinite()) return {};
  const Eigen::EigenSolver<MatX> eig(lin.A, true);
  const Eigen::VectorXcd& ev = eig.eigenvalues();
  const Eigen::MatrixXcd V = eig.eigenvectors();  // (built anew by every call: once here)
  const int n = static_cast<int>(lin.A.rows()) / 2;
  double largest = 0;
  for (Eigen::Index i = 0; i < ev.size(); ++i) largest = std::max(largest, std::abs(ev[i]));
  const double jordan_noise = 4 * std::sqrt(std::numeric_limits<double>::epsilon() *
                                            lin.A.cwiseAbs().colwise().sum().maxCoeff());
  std::vector<Mode> out;
  for (Eigen::Index i = 0; i < ev.size(); ++i) {
    Mode md;
    md.lambda = ev[i];
    md.omega = std::abs(ev[i]);
    // A zero eigenvalue of a free coordinate (a rigid-body mode) is a 2 × 2 Jordan block of A,
    // which round-off ε‖A‖ splits into ±√(ε‖A‖): below that, ω is no frequency.
    const double tiny = std::max(1e-9 * std::max(largest, 1e-300), jordan_noise);
    if (md.omega <= tiny) {
      md.kind = ModeKind::None;
    } else if (std::abs(ev[i].imag()) > 1e-9 * md.omega) {
      md.kind = ModeKind::Oscillatory;
      if (dissipative_model && ev[i].real() <= 0) md.zeta = -ev[i].real() / md.omega;
    } else {
      // A real eigenvalue with its mirror −λ among the others: a saddle.
      bool mirrored = false;
      for (Eigen::Index j = 0; j < ev.size(); ++j)
        mirrored = mirrored || (j != i && std::abs(ev[j] + ev[i]) <= 1e-3 * md.omega);
      md.kind = mirrored           ? ModeKind::Saddle
                : ev[i].real() < 0 ? ModeKind::Decaying
                                   : ModeKind::Growing;
    }
    // The coordinate that moves most: the largest entry of the eigenvector's q part.
    double best = -1;
    for (int a = 0; a < n; ++a)
      if (std::abs(V(a, i)) > best) {
        best = std::abs(V(a, i));
        md.coordinate = a;
      }
    out.push_back(md);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const Mode& a, const Mode& b) { return a.omega > b.omega; });
  return out;
}

double resolving_step(IntegratorKind kind, double omega, double tol) {
  constexpr double two_pi = 2 * std::numbers::pi;
  if (!(omega > 0) || !(tol > 0)) return std::numeric_limits<double>::infinity();
  double N = 0;
  if (kind == IntegratorKind::Rk4)
    N = std::pow(std::pow(two_pi, 5) / (120 * tol), 0.25);
  else if (kind == IntegratorKind::Euler)
    N = std::max(std::numbers::pi / tol, std::sqrt(std::pow(two_pi, 3) / (24 * tol)));
  else
    return 0;
  return two_pi / (N * omega);
}

double error_per_period(IntegratorKind kind, double omega, double dt) {
  constexpr double two_pi = 2 * std::numbers::pi;
  const double N = two_pi / (omega * dt);
  if (kind == IntegratorKind::Rk4) return std::pow(two_pi, 5) / (120 * std::pow(N, 4));
  if (kind == IntegratorKind::Euler)
    return std::max(std::numbers::pi / N, std::pow(two_pi, 3) / (24 * N * N));
  return NAN;
}

std::optional<double> baumgarte_stable_step(double omega, IntegratorKind kind) {
  Linearization lin;
  lin.A.resize(2, 2);
  lin.A << 0, 1, -omega * omega, -2 * omega;
  analyse(lin);
  return largest_stable_step(lin, kind);
}

std::string divergence_cause(const Model& m, IntegratorKind kind, double dt,
                             const std::string& setting, const VecX& q0, const VecX& qd0,
                             const VecX& tau0, double baumgarte) {
  const std::string method = std::string(integrator_name(kind)) + " at " + setting;
  if (dt <= 0)
    return method + ": the error control did not hold the solution; tighten rtol and atol" +
           (kind == IntegratorKind::Dopri ? std::string(", or use bdf for a stiff model")
                                          : std::string());
  constexpr int kLargest = 400;  // a dense eigenproblem of 2n beyond it takes seconds
  if (m.n() > kLargest)
    return method + " is likely beyond the stability limit of the model's stiffest mode (n = " +
           std::to_string(m.n()) + " is too large to find it here; femdyn check --states 1 " +
           "estimates it); use a smaller dt or dopri";
  Workspace ws(m);
  const Linearization lin = linearize(m, ws, q0, qd0, tau0, baumgarte);
  if (!lin.status.ok)
    return method + " diverged from a start state whose dynamics cannot be linearised (" +
           lin.status.message + "); use a smaller dt or dopri";
  const std::optional<double> limit = largest_stable_step(lin, kind);
  const std::vector<Mode> md = modes(lin, has_dampers(m));
  const std::string mode = md.empty() ? std::string("no mode") : md.front().text();
  // A step that is stable with margin and resolves the stiffest oscillation to 1e-3 a period.
  double advice = limit && std::isfinite(*limit) ? 0.5 * *limit : dt / 4;
  if (!md.empty() && md.front().kind == ModeKind::Oscillatory)
    advice = std::min(advice, resolving_step(kind, md.front().omega, 1e-3));
  // A dissipative stiffest mode is BDF's case; an undamped one must be resolved (dopri does).
  const bool dissipative = !md.empty() && md.front().dissipative();
  const std::string use =
      "; use dt ≤ " + format_short(advice) + " s or " + (dissipative ? "bdf" : "dopri");
  if (limit && std::isfinite(*limit) && dt > *limit)
    return method + " is beyond the stability limit of the stiffest mode at the start (" + mode +
           "; limit ≈ " + format_short(*limit) + " s)" + use;
  return method + " is within the linear stability limit of the start state (" +
         (limit && std::isfinite(*limit) ? format_short(*limit) + " s" : std::string("none")) +
         ", stiffest mode " + mode +
         "), so the motion left the region where that holds (faster speeds, a stiffer posture) "
         "or the method's error accumulated" +
         use;
}

std::vector<SuspiciousBody> suspicious_bodies(const Model& m) {
  std::vector<SuspiciousBody> out;
  const int nb = static_cast<int>(m.bodies.size());
  const std::vector<MassProperties> p = body_mass_properties(m);
  // Each body's heaviest child, the first in file order among equals (-1: none with mass).
  std::vector<int> heaviest_child(nb, -1);
  for (int c = 0; c < nb; ++c) {
    const int parent = m.bodies[c].parent;
    if (parent >= 0 &&
        p[c].mass > (heaviest_child[parent] < 0 ? 0 : p[heaviest_child[parent]].mass))
      heaviest_child[parent] = c;
  }
  const auto flag = [&](int b, const std::string& why) {
    out.push_back({b, m.bodies[b].name, why});
  };
  for (int b = 0; b < nb; ++b) {
    // Neighbours: the parent and the children, among bodies that carry mass (the parent first
    // among equals: it comes before its children).
    double heaviest = 0;
    std::string heaviest_name;
    for (const int c : {m.bodies[b].parent, heaviest_child[b]})
      if (c >= 0 && p[c].mass > heaviest) {
        heaviest = p[c].mass;
        heaviest_name = m.bodies[c].name;
      }
    const double mass = p[b].mass;
    if (mass > 0 && heaviest > 0 && mass < 1e-6 * heaviest)
      flag(b, "near-zero mass: " + format_short(mass) + " kg, " + format_short(mass / heaviest) +
                  " of its neighbour '" + heaviest_name + "' (" + format_short(heaviest) +
                  " kg); where nothing heavier hangs "
                  "beyond it M^s loses about " +
                  format_short(std::log10(heaviest / mass)) +
                  " digits: merge it into its neighbour or give it a realistic mass");
    if (mass <= 0) continue;
    const Mat3 Ic = p[b].inertia_com();
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(0.5 * (Ic + Ic.transpose()));
    const Vec3 I = eig.eigenvalues();  // ascending
    if (I[2] <= 0) continue;           // a point mass: no rotational inertia by design
    if (I[0] < 1e-9 * I[2])
      flag(b, "near-zero principal inertia: " + format_short(I[0]) + " kg·m² against " +
                  format_short(I[2]) +
                  " (a thin rod or a point): rotations about that axis are ill-conditioned");
    else if (std::abs(I[0] + I[1] - I[2]) <= 1e-6 * I[2]) {
      // I1 + I2 = I3 is a lamina (a thin disc or plate): physically valid, worth a look.
      flag(b,
           "a flat body: its principal inertias meet the triangle inequality's boundary "
           "(I1 + I2 − I3 = " +
               format_short(I[0] + I[1] - I[2]) + " kg·m², I3 = " + format_short(I[2]) +
               "), as a thin disc or plate does; if the body is not flat, check the tensor");
      out.back().note = true;
    } else if (I[0] + I[1] - I[2] < 0)
      flag(b, "inertia violates the triangle inequality (I1 + I2 − I3 = " +
                  format_short(I[0] + I[1] - I[2]) + " kg·m², I3 = " + format_short(I[2]) +
                  "): no rigid body has it; a mistyped tensor");
  }
  return out;
}

}  // namespace femdyn
