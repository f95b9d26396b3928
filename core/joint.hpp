// The joint module: what each joint type contributes to the tree level, in one place.
//   revolute   turns by θ about its axis a (joint frame):  R = R_j Rot(a, θ), origin fixed
//   prismatic  slides by θ along a:                        R = R_j, origin + s θ
//   fixed      no coordinate
// A joint's DOF address is Joint::theta (its index in θ; -1 when fixed). Its motion subspace,
// in world axes about the world origin (core/spatial.hpp), with s = R_b a its world axis and
// p_b the body origin (= the joint origin after motion):
//   revolute S = (s, p_b × s),   prismatic S = (0, s).
#pragma once
#include <cmath>

#include "core/model.hpp"
#include "core/spatial.hpp"

namespace femdyn {

inline bool moves(const Joint& j) { return j.theta >= 0; }

// The joint frame after motion, in the parent body frame: R_pj Rot(a, θ) for a revolute joint,
// by Rodrigues with the products precomputed, R_pj (I + sin θ [a]× + (1 − cos θ) [a]×²).
inline Mat3 joint_rotation(const Joint& j, double theta) {
  if (j.type != JointType::Revolute) return j.R_pj;
  const double s = std::sin(theta), c = std::cos(theta);
  return j.R_pj + s * j.R_pj_K + (1 - c) * j.R_pj_K2;
}

// The joint's own force on θ: spring and damper, −k (θ − θ_rest) − c θ̇ (θ̇ counted when given).
inline double spring_damper_force(const Joint& j, double theta, double theta_dot) {
  double f = 0;
  if (j.stiffness != 0) f -= j.stiffness * (theta - j.rest);
  if (j.damping != 0) f -= j.damping * theta_dot;
  return f;
}

inline Vec6 motion_subspace(const Joint& j, const Mat3& R_b, const Vec3& p_b) {
  const Vec3 s = R_b * j.axis;
  Vec6 S;
  if (j.type == JointType::Revolute)
    S << s, p_b.cross(s);
  else
    S << Vec3::Zero(), s;
  return S;
}

}  // namespace femdyn
