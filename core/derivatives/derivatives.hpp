// Analytic derivatives of the dynamics (Carpentier and Mansard, "Analytical Derivatives of Rigid
// Body Dynamics Algorithms", RSS 2018), over the element-assembled body inertias Λ_b in world
// axes about the world origin (core/spatial/spatial.hpp), as the Newton–Euler recursion
// (core/dynamics/newton_euler.hpp) computes τ.
//
// Convention. Every derivative is n × n over the rates v, one column per rate. A column with
// respect to q is the derivative along the tangent: ∂f/∂q_m = d/dε f(q ⊕ ε e_m) at ε = 0, with
// q ⊕ ξ of `integrate_posture` (core/kinematics/sampling.hpp): q + ξ on a flat joint; on a
// spherical joint q ⊗ exp(ξ), on a free joint (p + R ξ_p, q ⊗ exp(ξ_r)) — the body turns and moves
// in its own axes. v, q̈ and τ are held fixed along it.
//
// Inverse dynamics τ(q, v, q̈) = M^s q̈ + h − Q|_{τ=0}. For a rate m of body b(m), moving q_m
// moves the subtree of b(m) rigidly by the twist S_m (its column, world axes about the origin).
// With V̄, ā the joint's velocity and acceleration before its columns that move with it (the
// parent's, plus the columns fixed in the parent's frame), the bodies i below b(m) see
//   ∂V_i/∂q_m = S_m × V_i + δV_m,                δV_m = V̄ × S_m,
//   ∂a_i/∂q_m = S_m × a_i − S_m × ā + δV_m × (V_i − V̄),
//   ∂I_i/∂q_m = S_m ×* I_i − I_i S_m×,
// so that the subtree's force F_b = Σ_{i ⪰ b} f_i (f_i = I_i a_i + V_i ×* I_i V_i − f^ext_i)
// changes by S_m ×* F_b plus
//   Dev_m(b) = I^c_b y_m + B^c_b δV_m + L^c_b S_m,ω,     y_m = −S_m × ā − δV_m × V̄,
//   B_i x = V_i ×* I_i x − I_i (V_i × x) + x ×* (I_i V_i)       (B^c_b = Σ_{i ⪰ b} B_i),
//   L_i: a point load f at x gives (x × (s × f), s × f), a body torque t gives (s × t, 0);
// and ∂a_i/∂v_m = V_f × S_m + S_m × (V_i − V̄) (V_f the velocity of the frame S_m is fixed in),
//   ∂F_b/∂v_m = I^c_b z_m + B^c_b S_m,     z_m = V_f × S_m − S_m × V̄.
// With τ_c = S_cᵀ F_b(c), and b the deeper of b(c), b(m):
//   ∂τ_c/∂q_m = S_cᵀ Dev_m(b) + [S_c does not move with q_m] S_cᵀ (S_m ×* F_b(m)),
//   ∂τ_c/∂v_m = S_cᵀ (I^c_b z_m + B^c_b S_m),
// then the joints' own forces (spring k, damper c, Coulomb F_c/v_s sech²(θ̇/v_s), stop) and the
// coupling level, ∂τ_q/∂q = Cᵀ (∂τ_θ/∂θ) C. O(n · depth): two dot products per pair.
//
// Forward dynamics q̈ = (M^s)⁻¹ (τ − (h − Q|_{τ=0})):
//   ∂q̈/∂q = −(M^s)⁻¹ ∂τ/∂q|_{q̈},   ∂q̈/∂v = −(M^s)⁻¹ ∂τ/∂v|_{q̈},   ∂q̈/∂τ = (M^s)⁻¹,
// (M^s)⁻¹ and the products are core/derivatives/inverse_mass.hpp: on the articulated route one
// O(n · bodies) sweep over the factorisation forward_dynamics leaves forms (M^s)⁻¹'s diagonal
// blocks, and each column of ∂τ/∂· is multiplied over its non-zero rows only.
//
// Two-point springs (core/derivatives/springs.hpp) and elements spanning bodies
// (core/derivatives/spans.hpp) add their terms to ∂τ_θ/∂θ, ∂τ_θ/∂θ̇ as forces at body points;
// a nonlinear coupling level θ = g(q) chains the tree's derivatives through g
// (core/derivatives/coupling.hpp); closed loops differentiate the constrained equations at
// Baumgarte's rate ω (core/derivatives/loops.hpp), ∂q̈/∂τ then the projected inverse.
//
// Covered: trees of every joint type, free bases, joint springs, dampers, Coulomb friction,
// stops, rotors, gravity, point loads and body torques, linear couplings and coupling laws
// (linear, polynomial, spline, four-bar), two-point springs, and elements spanning bodies that use
// only their nodes' translations (the rod), closed loops (every constraint form) over uncoupled
// joints. Refused with a one-line ModelError: closed loops over coupled joints, an explicit
// correlation table, an element whose velocity forces are not rigid, and a spanning element
// with rotations or a velocity force.
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/derivatives/coupling.hpp"
#include "core/derivatives/inverse_mass.hpp"
#include "core/derivatives/loops.hpp"
#include "core/derivatives/spans.hpp"
#include "core/derivatives/springs.hpp"
#include "core/workspace/status.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

using Mat63 = Eigen::Matrix<double, 6, 3>;

// A body's (or a subtree's) velocity inertia B = [[top, 0], [−2 [h_f]×, 0]] (derivatives.cpp,
// velocity_inertia): only its left column is non-zero, so it is kept as a 3 × 3 and a 3-vector.
struct VelocityInertia {
  Mat3 top = Mat3::Zero();
  Vec3 hf = Vec3::Zero();

  // B x = (top x_ω, −2 h_f × x_ω).
  Vec6 operator*(const Vec6& x) const {
    Vec6 f;
    f.head<3>().noalias() = top * x.head<3>();
    f.tail<3>() = -2 * cross3(hf, x.head<3>());
    return f;
  }
  // The angular part of Bᵀ s = (topᵀ s_ω + 2 h_f × s_v, 0).
  Vec3 transpose_times(const Vec6& s) const {
    Vec3 u;
    u.noalias() = top.transpose() * s.head<3>();
    u += 2 * cross3(hf, s.tail<3>());
    return u;
  }
  VelocityInertia& operator+=(const VelocityInertia& o) {
    top += o.top;
    hf += o.hf;
    return *this;
  }
};

// The results and buffers of the derivatives, sized once for a model: no allocation per call
// after the first.
struct DerivativeWorkspace {
  explicit DerivativeWorkspace(const Model& model);  // throws ModelError if not covered

  MatX dtau_dq, dtau_dv;  // ∂τ/∂q, ∂τ/∂v (n × n)
  MatX dqdd_dq, dqdd_dv, Minv;  // ∂q̈/∂q, ∂q̈/∂v, ∂q̈/∂τ = (M^s)⁻¹ (n × n; loops: projected)
  VecX qdd;                     // q̈ of the last forward derivatives

  // Per body (world axes about the origin).
  std::vector<Vec6> V, a, V_bar, a_bar, F;
  std::vector<RigidInertia> Ic;
  std::vector<VelocityInertia> Bc;
  std::vector<Mat63> Lc;
  // Per rate of θ̇.
  std::vector<Vec6> S, dV, y, z, uI;
  std::vector<Vec3> uB, uL;  // uB: the angular part of B^cᵀ S (its linear part is 0)
  VecX theta_dot, theta_ddot, column;
  MatX Kq, Kv, KC;  // the joint-level ∂τ_θ/∂θ, ∂τ_θ/∂θ̇ and K C (coupled models only)
  bool loads = false;
  InverseMassSweep sweep;  // (M^s)⁻¹ and −(M^s)⁻¹ ∂τ/∂· (core/derivatives/inverse_mass.hpp)
  SpringDerivatives springs;  // the two-point springs' buffers (core/derivatives/springs.hpp)
  SpanDerivatives spans;      // the spanning elements' (core/derivatives/spans.hpp)
  std::unique_ptr<LawDerivatives> law;  // a coupling law's chain (core/derivatives/coupling.hpp)
  // Closed loops (core/derivatives/loops.hpp): forward_dynamics_derivatives solves the
  // constrained equations at Baumgarte's rate `baumgarte` (1/s; the simulator's default unless
  // set), with these buffers and their own LoopWorkspace.
  std::unique_ptr<LoopDerivatives> loops;
  double baumgarte = kDefaultBaumgarte;
};

// "" if the derivatives cover `model`, else why not (one line).
std::string derivatives_unsupported(const Model& model);

// ∂τ/∂q, ∂τ/∂v of inverse dynamics at (q, v, q̈) into d.dtau_dq, d.dtau_dv. Leaves the body
// poses in ws and nothing else of ws changed (a factorisation there stays valid).
void inverse_dynamics_derivatives(const Model& model, Workspace& ws, DerivativeWorkspace& d,
                                  const VecX& q, const VecX& qd, const VecX& qdd);

// q̈ (into ws.qdd and d.qdd), then ∂q̈/∂q, ∂q̈/∂v and (M^s)⁻¹ into d. A failed forward dynamics
// (singular M^s) is returned as is. A model with closed loops: those of the constrained
// equations at Baumgarte's rate d.baumgarte (constrained_forward_dynamics_derivatives), d.Minv
// the projected inverse M⁻¹ − Y S⁺ Yᵀ; a dead point is a failed Status.
Status forward_dynamics_derivatives(const Model& model, Workspace& ws, DerivativeWorkspace& d,
                                    const VecX& q, const VecX& qd, const VecX& tau);

// A = ∂(ξ̇, v̇)/∂(ξ, v) at ξ = 0 (2n × 2n) and B = ∂(ξ̇, v̇)/∂u (2n × n_a) from the forward
// derivatives in d at (q, v), u the actuated coordinates' τ (τ = S u, S = I[:, model.actuated]:
// B's columns are those of [0; M⁻¹] at the actuated rates, docs/control.md#actuation).
// ∂ξ̇/∂ξ is each joint type's chart_rate_jacobian (core/kinematics/sampling.hpp): 0 on flat
// joints, −½ [ω]× for a spherical one (ξ̇ = J_r(ξ)⁻¹ ω), and −[v_p]× besides for a free one.
void linearization(const Model& model, const DerivativeWorkspace& d, const VecX& qd, MatX& A,
                   MatX& B);

// The linearisation every door gives at the state (q, v, τ) as it is given (`femdyn linearize`,
// Model.linearize and its batch): forward_dynamics_derivatives, then linearization. Its failure,
// or A or B not finite (a state that overflows double precision), is the failed Status, its
// message to follow "at this state ".
Status linearize_state(const Model& model, Workspace& ws, DerivativeWorkspace& d, const VecX& q,
                       const VecX& qd, const VecX& tau, MatX& A, MatX& B);

}  // namespace femdyn
