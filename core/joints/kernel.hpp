// The joint kernel (spatial_v2's jcalc, Pinocchio's joint models): what every joint type gives
// the algorithms, each type in its own file pair (core/joints/<type>.hpp) and here one switch.
// Algorithms see joints only through these functions and the types' static members.
//
// A joint joins the parent body P to the child B through its joint frame, fixed on P at
// (R_pj, p_pj). Its nq coordinates θ_J (at Joint::idx_q in θ) place B:
//   R_B = R_P R_pj R_J(θ_J),   p_B = p_P + R_P (p_pj + d_J),   d_J = R_pj p_J(θ_J)
// (J::pose gives R_pj R_J and d_J, the displacement apart from p_pj, so that the roots' places
// can be taken from the reference point without the world's large numbers:
// core/kinematics/kinematics.cpp) Its nv rates θ̇_J (at Joint::idx_v in θ̇) move B relative to P,
// about B's origin:
//   (Δω, Δv) = S_J θ̇_J,   S_J = [S_ω; S_v] (6 × nv)              (J::S_angular, J::S_linear)
// Each column of S_J is constant in one of two frames: in B (given in B's axes), or in the
// parent's joint frame (J::in_parent(k); given in P's axes). In world axes a column is
// s = R_B S or s = R_P S; as a spatial motion about the world origin (core/spatial/spatial.hpp) it
// is (s_ω, s_v + p_B × s_ω). Its rate of change is then the frame's: ṡ = V_B × s or V_P × s, so
//   c_J = Ṡ_J θ̇_J = V_B × (S_B θ̇_B) + V_P × (S_P θ̇_P)     (the columns fixed in B, in P),
// the whole bias a joint type needs, with no per-type derivative (Featherstone's c_J).
// A type whose coordinates are not a vector space (spherical, free: nq ≠ nv) says how to move
// on its configuration manifold: q ⊕ ξ (J::integrate), q₁ ⊖ q₀ (J::difference), and ξ̇ in the
// chart ξ ↦ q_c ⊕ ξ (J::chart_rate); core/joints/flat.hpp gives the rest of them q + ξ.
#pragma once
#include <array>
#include <random>
#include <string>
#include <string_view>

#include "core/joints/fixed.hpp"
#include "core/joints/free.hpp"
#include "core/joints/helical.hpp"
#include "core/joints/parameters.hpp"
#include "core/joints/planar.hpp"
#include "core/joints/prismatic.hpp"
#include "core/joints/revolute.hpp"
#include "core/joints/spherical.hpp"
#include "core/joints/universal.hpp"

namespace femdyn {

// f(J{}) out of line: the types of several rates are kept out of the hot loops that the
// one-rate types (most joints of most trees) run through inlined.
template <class J, class F>
[[gnu::noinline]] decltype(auto) visit_outlined(F& f) {
  return f(J{});
}

// f(J{}) for the joint type J of `type`: the one switch over the joint types.
template <class F>
[[gnu::always_inline]] inline decltype(auto) visit_joint(JointType type, F&& f) {
  switch (type) {
    case JointType::Revolute:
      return f(RevoluteJoint{});
    case JointType::Prismatic:
      return f(PrismaticJoint{});
    case JointType::Helical:
      return visit_outlined<HelicalJoint>(f);
    case JointType::Universal:
      return visit_outlined<UniversalJoint>(f);
    case JointType::Planar:
      return visit_outlined<PlanarJoint>(f);
    case JointType::Spherical:
      return visit_outlined<SphericalJoint>(f);
    case JointType::Free:
      return visit_outlined<FreeJoint>(f);
    case JointType::Fixed:
      break;
  }
  return f(FixedJoint{});
}

inline bool moves(const Joint& j) { return j.nv > 0; }

// What the type reads of its description (core/joints/parameters.hpp).
inline JointParameters joint_parameters(JointType type) {
  return visit_joint(type, []<class J>(J) {
    JointParameters p{J::axes, {}, J::nv > 0};
    if constexpr (requires { J::scalars; }) p.scalars = J::scalars;
    return p;
  });
}
// The number `key` as `type` declares it, or null where the type takes no such number.
const JointScalar* joint_scalar(JointType type, std::string_view key);
// Whether some joint type takes the number `key`.
bool is_joint_scalar(std::string_view key);
// Why `key` is refused on a joint of another type: "only a helical joint has a pitch".
std::string joint_scalar_refusal(std::string_view key);
// Why a moving joint of `type` that reads no axis refuses one: "a spherical joint turns about
// every axis: it takes no axis"; and why a type of fewer than two axes refuses `axis2`.
std::string joint_axis_refusal(JointType type);
std::string joint_axis2_refusal();

// Whether column k of the joint is fixed in the parent's joint frame (else in B).
inline bool column_in_parent(const Joint& j, int k) {
  return visit_joint(j.type, [&]<class J>(J) { return J::in_parent(k); });
}

// B's orientation and origin in its parent's frame at the joint coordinates θ (all of them).
inline void joint_pose(const Joint& j, const VecX& theta, Mat3& R, Vec3& p) {
  const double* q = j.idx_q >= 0 ? theta.data() + j.idx_q : nullptr;
  visit_joint(j.type, [&]<class J>(J) { J::pose(j, q, R, p); });
}

// Column k of S_J in world axes: its angular and linear halves, at B's origin. R_P is the
// parent's orientation (the identity for the world), read only by columns fixed in P.
template <class J>
[[gnu::always_inline]] inline Vec3 world_angular(const Joint& j, const Mat3& R_B, const Mat3& R_P,
                                                 int k) {
  if constexpr (J::angular) return (J::in_parent(k) ? R_P : R_B) * J::S_angular(j, k);
  return Vec3::Zero();
}
template <class J>
[[gnu::always_inline]] inline Vec3 world_linear(const Joint& j, const Mat3& R_B, const Mat3& R_P,
                                                int k) {
  if constexpr (J::linear) return (J::in_parent(k) ? R_P : R_B) * J::S_linear(j, k);
  return Vec3::Zero();
}

// Column k of S_J as a spatial motion about the world origin: (s_ω, s_v + p_B × s_ω).
template <class J>
[[gnu::always_inline]] inline Vec6 spatial_column(const Joint& j, const Mat3& R_B, const Mat3& R_P,
                                                  const Vec3& p_B, int k) {
  Vec6 S;
  const Vec3 w = world_angular<J>(j, R_B, R_P, k);
  S.head<3>() = w;
  if constexpr (J::angular && J::linear)
    S.tail<3>() = world_linear<J>(j, R_B, R_P, k) + cross3(p_B, w);
  else if constexpr (J::angular)
    S.tail<3>() = cross3(p_B, w);
  else
    S.tail<3>() = world_linear<J>(j, R_B, R_P, k);
  return S;
}
[[gnu::always_inline]] inline Vec6 spatial_column(const Joint& j, const Mat3& R_B, const Mat3& R_P,
                                                  const Vec3& p_B, int k) {
  return visit_joint(
      j.type, [&]<class J>(J) __attribute__((always_inline)) {
        return spatial_column<J>(j, R_B, R_P, p_B, k);
      });
}

// All nv columns of S_J as spatial motions about the world origin, into S[0 .. nv).
inline void spatial_columns(const Joint& j, const Mat3& R_B, const Mat3& R_P, const Vec3& p_B,
                            Vec6* S) {
  visit_joint(j.type, [&]<class J>(J) {
    for (int k = 0; k < J::nv; ++k) S[k] = spatial_column<J>(j, R_B, R_P, p_B, k);
  });
}

// The joint's part of a body's motion in the recursions (spatial, world axes, about the origin),
// for a joint that moves (nv > 0): its columns S_k into S[0 .. nv), then, with V = V_P on entry,
// V += v_J and a += V_B × v_J,B + V_P × v_J,P (+ Σ S_k θ̈_k when `acc` is given), v_J = Σ S_k θ̇_k
// split by the frame each column is fixed in; the rates at `rate` and `acc` (each indexed from
// the joint's first rate).
template <class J>
[[gnu::always_inline]] inline void add_joint_motion(const Joint& j, const Mat3& R_B,
                                                    const Mat3& R_P, const Vec3& p_B,
                                                    const double* rate, const double* acc, Vec6* S,
                                                    Vec6& V, Vec6& a) {
  if constexpr (J::nv == 1 && !J::in_parent(0)) {  // one column fixed in B: no zero terms
    S[0] = spatial_column<J>(j, R_B, R_P, p_B, 0);
    const Vec6 vj = S[0] * rate[0];
    V += vj;
    a += cross_motion(V, vj);
    if (acc) a += S[0] * acc[0];
    return;
  }
  Vec6 vj = Vec6::Zero(), vj_parent = Vec6::Zero();
  for (int k = 0; k < J::nv; ++k) {
    S[k] = spatial_column<J>(j, R_B, R_P, p_B, k);
    (J::in_parent(k) ? vj_parent : vj) += S[k] * rate[k];
  }
  const Vec6 V_P = V;
  V += vj + vj_parent;
  a += cross_motion(V, vj);
  if constexpr (J::in_parent(0) || J::in_parent(J::nv - 1)) a += cross_motion(V_P, vj_parent);
  if (acc)
    for (int k = 0; k < J::nv; ++k) a += S[k] * acc[k];
}
[[gnu::always_inline]] inline void add_joint_motion(const Joint& j, const Mat3& R_B,
                                                    const Mat3& R_P, const Vec3& p_B,
                                                    const double* rate, const double* acc, Vec6* S,
                                                    Vec6& V, Vec6& a) {
  visit_joint(
      j.type, [&]<class J>(J) __attribute__((always_inline)) {
        add_joint_motion<J>(j, R_B, R_P, p_B, rate, acc, S, V, a);
      });
}

// Whether the point r of B (B's frame) stays fixed in the parent under every motion of the
// joint: S_ω,k × r + S_v,k = 0 for each column (relative to 1 + |r|).
inline bool fixes_point(const Joint& j, const Vec3& r) {
  return visit_joint(j.type, [&]<class J>(J) {
    const double tol = 1e-12 * (1.0 + r.norm());
    for (int k = 0; k < J::nv; ++k) {
      const Vec3 w = J::S_angular(j, k), v = J::S_linear(j, k);
      // A column fixed in P is in P's axes, r in B's: only the origin of B is sure to stay.
      const Vec3 r_k = J::in_parent(k) && !w.isZero() && r.norm() > tol ? Vec3::Constant(1) : r;
      if ((w.cross(r_k) + v).norm() > tol) return false;
    }
    return true;
  });
}

// B's orientation and origin in the parent's frame at the neutral configuration.
inline void neutral_pose(const Joint& j, Mat3& R, Vec3& p) {
  std::array<double, 7> q{};
  visit_joint(j.type, [&]<class J>(J) {
    J::neutral(q.data());
    J::pose(j, q.data(), R, p);  // (its displacement d)
  });
  p += j.p_pj;
}

// The joint's neutral configuration into q[0 .. nq): 0, or the identity rotation.
inline void neutral_configuration(const Joint& j, double* q) {
  visit_joint(j.type, [&]<class J>(J) { J::neutral(q); });
}

// Whether θ_J is a vector space (θ ⊕ ξ = θ + ξ, θ̇_J the derivative of θ_J).
inline bool is_flat(const Joint& j) {
  return visit_joint(j.type, []<class J>(J) { return J::flat; });
}

// out = q ⊕ ξ on the joint's configuration manifold (q, out: nq entries; ξ: nv).
inline void integrate_configuration(const Joint& j, const double* q, const double* xi,
                                    double* out) {
  visit_joint(j.type, [&]<class J>(J) { J::integrate(j, q, xi, out); });
}

// ξ = q₁ ⊖ q₀: the chart coordinates (nv) of q₁ around q₀.
inline void configuration_difference(const Joint& j, const double* q0, const double* q1,
                                     double* xi) {
  visit_joint(j.type, [&]<class J>(J) { J::difference(j, q0, q1, xi); });
}

// ξ̇ in the chart ξ ↦ q_c ⊕ ξ for the rates v (nv each).
inline void chart_rate(const Joint& j, const double* q_c, const double* xi, const double* v,
                       double* xi_dot) {
  visit_joint(j.type, [&]<class J>(J) { J::chart_rate(j, q_c, xi, v, xi_dot); });
}

// ∂ξ̇/∂ξ at ξ = 0 for the rates v: the joint's nv × nv block of the linearisation's top rows,
// row-major into A (zero on entry; 0 for a flat joint).
inline void chart_rate_jacobian(const Joint& j, const double* v, double* A) {
  visit_joint(j.type, [&]<class J>(J) { J::chart_rate_jacobian(j, v, A); });
}

// A random configuration of a joint of more than one rate into q[0 .. nq): each flat coordinate
// uniform within the type's half range (±π for angles), a rotation uniform over SO(3).
inline void random_configuration(const Joint& j, std::mt19937& rng, double* q) {
  std::normal_distribution<double> normal;
  visit_joint(j.type, [&]<class J>(J) {
    if constexpr (J::flat) {
      for (int k = 0; k < J::nq; ++k) {
        const double half = J::S_angular(j, k).isZero() ? J::kRandomHalfRange : 3.141592653589793;
        q[k] = std::uniform_real_distribution<double>(-half, half)(rng);
      }
    } else {
      const int rot = J::nq - 4;  // the quaternion is last
      for (int k = 0; k < rot; ++k)
        q[k] =
            std::uniform_real_distribution<double>(-J::kRandomHalfRange, J::kRandomHalfRange)(rng);
      Eigen::Vector4d g;
      for (int k = 0; k < 4; ++k) g[k] = normal(rng);  // normalised Gaussian: uniform on S³
      g.normalize();
      if (g[0] < 0) g = -g;
      for (int k = 0; k < 4; ++k) q[rot + k] = g[k];
    }
  });
}

// The rates w that move q(s) = q_c ⊕ sΔ at unit ds, and dw/ds (nv each): along q(s(t)) the
// joint's v = ṡ w and v̇ = s̈ w + ṡ² dw/ds. By default w = Δ, dw/ds = 0: true of a flat joint
// (θ = θ_c + sΔ) and of a ball (R = R_c exp(sΔ), ω = ṡ Δ in B); a type whose rates turn along
// the ray says so by J::ray_rates (the free joint: its v is in B's axes).
inline void ray_rates(const Joint& j, const double* delta, double s, double* w, double* dw) {
  visit_joint(j.type, [&]<class J>(J) {
    if constexpr (requires { J::ray_rates(j, delta, s, w, dw); })
      J::ray_rates(j, delta, s, w, dw);
    else
      for (int k = 0; k < J::nv; ++k) w[k] = delta[k], dw[k] = 0;
  });
}

// Whether rate k moves B by translation alone (a length, m), not by a turn (an angle, rad).
inline bool is_translation(const Joint& j, int k) {
  return visit_joint(j.type,
                     [&]<class J>(J) { return !J::angular || J::S_angular(j, k).isZero(); });
}

// The suffixes naming coordinate k and rate k of a joint of several ("qw", "wx"; "" for one).
inline std::string coordinate_name(const Joint& j, int k) {
  return visit_joint(j.type, [&]<class J>(J) { return std::string(J::coordinate_name(k)); });
}
inline std::string rate_name(const Joint& j, int k) {
  return visit_joint(j.type, [&]<class J>(J) { return std::string(J::rate_name(k)); });
}

// Compile: the type's sizes and the constants its pose uses.
inline void prepare_joint(Joint& j) {
  visit_joint(j.type, [&]<class J>(J) {
    j.nq = J::nq;
    j.nv = J::nv;
    J::prepare(j);
  });
}

// Half the width of the range random configurations are drawn from: ±π rad, ±0.5 m.
inline double type_random_half_range(JointType type) {
  return visit_joint(type, []<class J>(J) { return J::kRandomHalfRange; });
}
// The model's own where it gives one (a flexible bar's strains), else the type's.
inline double random_half_range(const Joint& j) {
  return j.sample_range > 0 ? j.sample_range : type_random_half_range(j.type);
}

}  // namespace femdyn
