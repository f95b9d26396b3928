// The joint kernel (spatial_v2's jcalc, Pinocchio's joint models): what every joint type gives
// the algorithms, each type in its own file pair (core/joints/<type>.hpp) and here one switch.
// Algorithms see joints only through these functions and the types' static members.
//
// A joint joins the parent body P to the child B through its joint frame, fixed on P at
// (R_pj, p_pj). Its nq coordinates θ_J (at Joint::idx_q in θ) place B:
//   R_B = R_P R_pj R_J(θ_J),   p_B = p_P + R_P (p_pj + R_pj p_J(θ_J))        (J::pose)
// Its nv rates θ̇_J (at Joint::idx_v in θ̇) move B relative to P, in B's axes about B's origin:
//   (Δω, Δv) = S_J θ̇_J,   S_J = [S_ω; S_v] (6 × nv)                         (J::S_angular,
//   S_linear)
// In world axes the columns are s_ω = R_B S_ω, s_v = R_B S_v; as a spatial motion about the
// world origin (core/spatial.hpp) a column is (s_ω, s_v + p_B × s_ω). Every type so far has
// S_J constant in B and nq = nv (its θ̇_J is the derivative of θ_J): c_J = Ṡ_J θ̇_J = 0.
#pragma once
#include <array>

#include "core/joints/fixed.hpp"
#include "core/joints/prismatic.hpp"
#include "core/joints/revolute.hpp"

namespace femdyn {

// f(J{}) for the joint type J of `type`: the one switch over the joint types.
template <class F>
decltype(auto) visit_joint(JointType type, F&& f) {
  switch (type) {
    case JointType::Revolute:
      return f(RevoluteJoint{});
    case JointType::Prismatic:
      return f(PrismaticJoint{});
    case JointType::Fixed:
      break;
  }
  return f(FixedJoint{});
}

inline bool moves(const Joint& j) { return j.nv > 0; }

// B's orientation and origin in its parent's frame at the joint coordinates θ (all of them).
inline void joint_pose(const Joint& j, const VecX& theta, Mat3& R, Vec3& p) {
  const double* q = j.idx_q >= 0 ? theta.data() + j.idx_q : nullptr;
  visit_joint(j.type, [&]<class J>(J) { J::pose(j, q, R, p); });
}

// Column k of S_J in world axes: its angular and linear halves, at B's origin.
template <class J>
Vec3 world_angular(const Joint& j, const Mat3& R_B, int k) {
  if constexpr (J::angular) return R_B * J::S_angular(j, k);
  return Vec3::Zero();
}
template <class J>
Vec3 world_linear(const Joint& j, const Mat3& R_B, int k) {
  if constexpr (J::linear) return R_B * J::S_linear(j, k);
  return Vec3::Zero();
}

// Column k of S_J as a spatial motion about the world origin: (s_ω, s_v + p_B × s_ω).
template <class J>
Vec6 spatial_column(const Joint& j, const Mat3& R_B, const Vec3& p_B, int k) {
  Vec6 S;
  const Vec3 w = world_angular<J>(j, R_B, k);
  S.head<3>() = w;
  S.tail<3>() = world_linear<J>(j, R_B, k) + cross3(p_B, w);
  return S;
}
inline Vec6 spatial_column(const Joint& j, const Mat3& R_B, const Vec3& p_B, int k) {
  return visit_joint(j.type, [&]<class J>(J) { return spatial_column<J>(j, R_B, p_B, k); });
}

// All nv columns of S_J as spatial motions about the world origin, into S[0 .. nv).
inline void spatial_columns(const Joint& j, const Mat3& R_B, const Vec3& p_B, Vec6* S) {
  visit_joint(j.type, [&]<class J>(J) {
    for (int k = 0; k < J::nv; ++k) S[k] = spatial_column<J>(j, R_B, p_B, k);
  });
}

// The joint's part of a body's motion in the recursions (spatial, world axes, about the origin),
// for a joint that moves (nv > 0): its columns S_k into S[0 .. nv), then V += v_J and
// a += V × v_J (+ Σ S_k θ̈_k when `acc` is given) with v_J = Σ S_k θ̇_k, the rates at `rate`
// and `acc` (each indexed from the joint's first rate). Only the columns depend on the type,
// so the per-type code stays a few products.
template <class J>
[[gnu::always_inline]] inline void add_joint_motion(const Joint& j, const Mat3& R_B,
                                                    const Vec3& p_B, const double* rate,
                                                    const double* acc, Vec6* S, Vec6& V, Vec6& a) {
  Vec6 vj = Vec6::Zero();
  for (int k = 0; k < J::nv; ++k) {
    S[k] = spatial_column<J>(j, R_B, p_B, k);
    vj += S[k] * rate[k];
  }
  V += vj;
  a += cross_motion(V, vj);
  if (acc)
    for (int k = 0; k < J::nv; ++k) a += S[k] * acc[k];
}
inline void add_joint_motion(const Joint& j, const Mat3& R_B, const Vec3& p_B, const double* rate,
                             const double* acc, Vec6* S, Vec6& V, Vec6& a) {
  visit_joint(j.type, [&]<class J>(J) { add_joint_motion<J>(j, R_B, p_B, rate, acc, S, V, a); });
}

// The joint's own generalized force on a 1-DOF joint's coordinate: its spring and damper,
// −k (θ − θ_rest) − c θ̇.
inline double spring_damper_force(const Joint& j, double theta, double theta_dot) {
  double f = 0;
  if (j.stiffness != 0) f -= j.stiffness * (theta - j.rest);
  if (j.damping != 0) f -= j.damping * theta_dot;
  return f;
}

// Whether the point r of B (B's frame) stays fixed in the parent under every motion of the
// joint: S_ω,k × r + S_v,k = 0 for each column (relative to 1 + |r|).
inline bool fixes_point(const Joint& j, const Vec3& r) {
  return visit_joint(j.type, [&]<class J>(J) {
    for (int k = 0; k < J::nv; ++k)
      if ((J::S_angular(j, k).cross(r) + J::S_linear(j, k)).norm() > 1e-12 * (1.0 + r.norm()))
        return false;
    return true;
  });
}

// B's orientation and origin in the parent's frame at θ_J = 0.
inline void neutral_pose(const Joint& j, Mat3& R, Vec3& p) {
  const std::array<double, 7> zero{};
  visit_joint(j.type, [&]<class J>(J) { J::pose(j, zero.data(), R, p); });
}

// Whether rate k moves B by translation alone (a length, m), not by a turn (an angle, rad).
inline bool is_translation(const Joint& j, int k) {
  return visit_joint(j.type,
                     [&]<class J>(J) { return !J::angular || J::S_angular(j, k).isZero(); });
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
inline double random_half_range(const Joint& j) {
  return visit_joint(j.type, []<class J>(J) { return J::kRandomHalfRange; });
}

}  // namespace femdyn
