#include "cli/check_modes.hpp"

#include <Eigen/QR>
#include <algorithm>
#include <numbers>

#include "core/model/names.hpp"
#include "sim/statics.hpp"

namespace femdyn::cli {

NaturalModes natural_modes(const Args& a, const Model& m) {
  NaturalModes out;
  if (!m.constraints.empty()) {
    out.missing = "closed loops (statics does not take them yet)";
    return out;
  }
  if (!m.prescribed.empty()) {
    out.missing = "joint '" + m.prescribed[0].joint + "' is prescribed in time: no rest";
    return out;
  }
  const StaticsResult rest = solve_statics(read_spec(a.positional[0], load_options(a)), {});
  if (!rest.status.ok) {
    out.missing = "no equilibrium: " + rest.status.message;
    return out;
  }
  Workspace ws(m);
  const VecX zero = VecX::Zero(m.n());
  const Linearization lin = linearize(m, ws, rest.q, zero, zero, 0);
  if (!lin.status.ok) {
    out.missing = "the linearisation at the equilibrium failed: " + lin.status.message;
    return out;
  }
  for (const Mode& x : modes(lin, has_dampers(m))) {
    if (x.kind != ModeKind::None && x.lambda.real() > 1e-9 * std::max(1.0, x.omega))
      ++out.unstable;  // (a rigid-body mode's round-off is no instability)
    if (x.kind == ModeKind::Oscillatory && x.lambda.imag() > 0) out.oscillatory.push_back(x);
  }
  // Rigid-body modes: the coordinates no spring holds, n − rank K, K = −M^s ∂q̈/∂q (A's lower
  // left block is −M⁻¹K, of K's rank), whether a damper acts on them or not.
  const int n = m.n();
  out.rigid =
      n - static_cast<int>(Eigen::ColPivHouseholderQR<MatX>(lin.A.bottomLeftCorner(n, n)).rank());
  std::sort(out.oscillatory.begin(), out.oscillatory.end(),
            [](const Mode& p, const Mode& q) { return p.lambda.imag() < q.lambda.imag(); });
  return out;
}

namespace {

std::string one_mode(const Model& m, const Mode& x) {
  const double w = x.lambda.imag();
  std::string s = format_short(w) + " rad/s (" + format_short(w / (2 * std::numbers::pi)) + " Hz)";
  if (x.coordinate >= 0) s += " in '" + m.coordinate_names[x.coordinate] + "'";
  return s;
}

}  // namespace

std::string natural_modes_text(const Model& m, const NaturalModes& modes) {
  if (!modes.missing.empty()) return "natural modes: not listed (" + modes.missing + ")";
  std::string s = "natural modes at rest (the static equilibrium, q̇ = 0): " +
                  std::to_string(modes.oscillatory.size()) + " oscillatory";
  if (modes.unstable) s += ", " + std::to_string(modes.unstable) + " unstable (a falling posture)";
  if (modes.rigid) s += ", " + std::to_string(modes.rigid) + " rigid-body (0 rad/s)";
  const std::size_t shown = std::min<std::size_t>(6, modes.oscillatory.size());
  for (std::size_t k = 0; k < shown; ++k)
    s += (k ? "; " : "; lowest ") + one_mode(m, modes.oscillatory[k]);
  if (modes.oscillatory.size() > shown) s += "; … highest " + one_mode(m, modes.oscillatory.back());
  return s;
}

Json natural_modes_json(const Model& m, const NaturalModes& modes) {
  Json list = Json::array();
  for (const Mode& x : modes.oscillatory)
    list.push_back({{"omega", x.lambda.imag()},
                    {"hz", x.lambda.imag() / (2 * std::numbers::pi)},
                    {"damping_ratio", -x.lambda.real() / std::abs(x.lambda)},
                    {"coordinate",
                     x.coordinate >= 0 ? Json(m.coordinate_names[x.coordinate]) : Json(nullptr)}});
  Json j = {{"oscillatory", list}, {"unstable", modes.unstable}, {"rigid", modes.rigid}};
  j["missing"] = modes.missing.empty() ? Json(nullptr) : Json(modes.missing);
  return j;
}

}  // namespace femdyn::cli
