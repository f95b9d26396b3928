// What the derivatives of forces at body points share (core/derivatives/springs.hpp, the
// two-point springs; core/derivatives/spans.hpp, the elements spanning bodies): a point x fixed
// on body b, moved by the rates on b's path. In world axes about the origin
// (core/spatial/spatial.hpp), with S_m = (ω_m, v_m) a rate's column and J_m(x) = v_m + ω_m × x its
// velocity at x, along the tangent θ ⊕ ε e_m (m on b's path; the subtree of m's body turns rigidly
// by S_m):
//   ∂x/∂θ_m = J_m(x),
//   ∂J_c(x)/∂θ_m = ω_m × J_c(x)  where S_c moves with θ_m (c below m, or c of m's joint and
//                                fixed in its body),   ω_c × J_m(x) otherwise,
// so that a force F held fixed at x, τ_c = J_c(x)ᵀ F, gives ∂τ_c/∂θ_m = ω_mᵀ (J_c × F) or
// ω_cᵀ (J_m × F). The point's velocity ẋ = v_O + ω × x and acceleration ẍ = a_O + α × x + ω × ẋ
// (V = (ω, v_O), a = (α, a_O) the body's, a with the base's −g) follow from the recursion's
//   ∂V/∂θ_m = S_m × (V − V̄),   ∂a/∂θ_m = S_m × (a − ā) + (V̄ × S_m) × (V − V̄),
//   ∂V/∂θ̇_m = S_m,             ∂a/∂θ̇_m = V_f × S_m + S_m × (V − V̄)
// (V̄, ā: the motion before m's columns that move with it; V_f: the frame S_m is fixed in), by
//   ∂ẋ = ∂v_O + ∂ω × x + ω × ∂x,   ∂ẍ = ∂a_O + ∂α × x + α × ∂x + ∂ω × ẋ + ω × ∂ẋ.
#pragma once
#include <vector>

#include "core/spatial/spatial.hpp"

namespace femdyn {

struct Model;
struct DerivativeWorkspace;

// The velocity at the world point x of the motion V = (ω, v_O): v_O + ω × x.
inline Vec3 point_velocity(const Vec6& V, const Vec3& x) {
  return V.tail<3>() + V.head<3>().cross(x);
}

// The rates on body b's path to the world (b = −1: none), deepest first, into `path`.
void rates_on_path(const Model& m, int b, std::vector<int>& path);

// Kq(c, m) += ∂(J_c(x)ᵀ F)/∂θ_m at F fixed, for c, m on `path` (x's): the turning of the point
// Jacobians. `arm` (per rate) is scratch.
void add_point_turning(const Model& m, const DerivativeWorkspace& d, const Vec3& x, const Vec3& F,
                       const std::vector<int>& path, std::vector<Vec3>& arm, MatX& Kq);

// Kq(c, m) += ∂(ω_cᵀ t)/∂θ_m at a torque t fixed, for c, m on `path`: the turning of the
// angular columns, ∂ω_c/∂θ_m = ω_m × ω_c where S_c moves with θ_m (else 0).
void add_axis_turning(const Model& m, const DerivativeWorkspace& d, const Vec3& t,
                      const std::vector<int>& path, MatX& Kq);

// The body's ∂V/∂θ_r, ∂a/∂θ_r (r on its path; a with the base's −g, which cancels).
void body_position_derivative(const Model& m, const DerivativeWorkspace& d, int body, int r,
                              Vec6& dV, Vec6& da);
// Its ∂a/∂θ̇_r (∂V/∂θ̇_r = S_r).
Vec6 body_rate_derivative(const Model& m, const DerivativeWorkspace& d, int body, int r);

// A point x on body b and its motion, with the derivatives of ẋ and ẍ along θ_r and θ̇_r.
struct PointMotion {
  int body = -1;
  Vec3 x = Vec3::Zero(), x_dot = Vec3::Zero(), x_ddot = Vec3::Zero();  // ẍ with −g
};
PointMotion point_motion(const DerivativeWorkspace& d, int body, const Vec3& x);
// ∂ẋ/∂θ_r and ∂ẍ/∂θ_r (r on the point's path).
void point_position_derivative(const Model& m, const DerivativeWorkspace& d, const PointMotion& p,
                               int r, Vec3& dx_dot, Vec3& dx_ddot);
// ∂ẍ/∂θ̇_r (r on the point's path; ∂ẋ/∂θ̇_r = J_r(x)).
Vec3 point_rate_derivative(const Model& m, const DerivativeWorkspace& d, const PointMotion& p,
                           int r);

}  // namespace femdyn
