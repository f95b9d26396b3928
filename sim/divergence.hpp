// A numerical solution that diverges (docs/simulation.md#divergence), told from the energy
// balance E(t) − E(0) = W(t) that the exact motion keeps (sim/motion.hpp). Dampers only take
// energy out, so the energy the state holds beyond what the forces supplied,
//
//   gain(t) = E(t) − E(0) − max(0, max_{s≤t} W(s)),
//
// is at most the integration error for a motion that is being followed. The solution diverges
// when that gain dwarfs every energy the motion was given and is most of what the state holds:
//
//   gain > 10 S   and   gain > ½ T(t),        S = S₀ + max_{s≤t} max(0, W(s)),
//   S₀ = max(|E(0)|, T(0), |V(0)|, Σ_i |F_i| |x_i(0)|),
//
// F_i the constant nodal forces (gravity, loads) and x_i their nodes' positions at the start
// (the potential they can exchange about the world origin). An unstable explicit step grows the
// state geometrically, so gain overtakes 10 S within a few steps of the growth becoming
// visible, long before an overflow or a matrix that the blown-up state makes singular; and a
// run that merely loses accuracy (gain a fraction of S) is not called diverged. While a run
// goes on, a divergence is confirmed by the gain doubling after it first exceeded the bounds
// (one more look: a transient swing that decays is not one); a run that fails is diverged if
// its last good state exceeds them.
//
// The fixed scale of the reported energy balance is S₀ + max_{s≤t} |W(s)| (`scale()`): the
// energy the motion started with plus the work done, which does not grow with the error.
#pragma once
#include <algorithm>
#include <cmath>

#include "core/dynamics/equations.hpp"

namespace femdyn {

class DivergenceWatch {
 public:
  // At the start of a run: E(0) and Σ_i |F_i| |x_i(0)|.
  void start(const Energy& E0, double potential_reach, double qd_norm) {
    E0_ = E0;
    S0_ = std::max({std::abs(E0.total()), E0.kinetic, std::abs(E0.potential), potential_reach});
    max_work_ = max_abs_work_ = 0;
    qd_looked_ = std::max(qd_norm, kQdFloor);
    gain_ = first_exceeding_ = 0;
    confirmed_ = false;
  }
  // The energy needs a look when ‖q̇‖∞ has doubled since the last look: a diverging explicit
  // step grows the rates geometrically, and a look costs one evaluation of M^s.
  bool due(double qd_norm) const { return !(qd_norm <= 2 * qd_looked_); }
  // The energy at this state (E, W) counted as supplied from now on: a look that exceeded the
  // bounds but that theory does not call unstable (a controller inside f, whose supply W cannot
  // show: ControlLoop) raises S₀ to it, so that only a further tenfold growth looks again.
  void accept(const Energy& E, double W) {
    S0_ = std::max({S0_, std::abs(E.total()), E.kinetic, std::abs(E.potential), std::abs(W)});
    first_exceeding_ = 0;
    confirmed_ = false;
  }
  // Looks at the energy E and the work W at a state: true when the gain exceeds its bounds
  // there (above). A transient that then decays — a step near a stability limit that swings
  // the energy up once, as RK4 does on a critically damped mode — is not a divergence, so
  // `confirmed()` asks for the gain to have grown twofold since it first exceeded them.
  bool look(const Energy& E, double W, double qd_norm) {
    qd_looked_ = std::max(qd_norm, kQdFloor);
    max_work_ = std::max(max_work_, W);
    max_abs_work_ = std::max(max_abs_work_, std::abs(W));
    gain_ = E.total() - E0_.total() - max_work_;
    const bool overflow = !std::isfinite(E.total()) || !std::isfinite(W);
    const bool exceeds = overflow || (gain_ > 10 * (S0_ + max_work_) && gain_ > 0.5 * E.kinetic);
    confirmed_ = overflow || (exceeds && first_exceeding_ > 0 && gain_ > 2 * first_exceeding_);
    if (!exceeds)
      first_exceeding_ = 0;
    else if (!(first_exceeding_ > 0) && std::isfinite(gain_))
      first_exceeding_ = gain_;
    return exceeds;
  }
  // The gain exceeded its bounds at an earlier look and has since doubled (or is not finite).
  bool confirmed() const { return confirmed_; }
  double initial_scale() const { return S0_; }          // S₀ (J)
  double scale() const { return S0_ + max_abs_work_; }  // S₀ + max |W| (J)
  double gain() const { return gain_; }                 // at the last look (J)
  double supplied() const { return S0_ + max_work_; }   // S (J)
  const Energy& initial() const { return E0_; }

 private:
  static constexpr double kQdFloor = 1e-6;  // rad/s or m/s: rates below it never trigger
  Energy E0_;
  double S0_ = 0, max_work_ = 0, max_abs_work_ = 0, qd_looked_ = kQdFloor, gain_ = 0;
  double first_exceeding_ = 0;  // the gain when it first exceeded its bounds (0: it does not)
  bool confirmed_ = false;
};

// Σ_i |F_i| |x_i|: the constant nodal forces (gravity and loads, per node) times their nodes'
// distances from the world origin, at the state of the last evaluation in ws.
double potential_reach(const Model& model, const Workspace& ws);

}  // namespace femdyn
