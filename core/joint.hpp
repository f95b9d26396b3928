// The joint module: what each joint type contributes to the tree level, in one place.
//   revolute   turns by θ about its axis a (joint frame):  R = R_j Rot(a, θ), origin fixed
//   prismatic  slides by θ along a:                        R = R_j, origin + s θ
//   fixed      no coordinate
// A joint's DOF address is Joint::theta (its index in θ; -1 when fixed). Its motion subspace,
// in world axes about the world origin (core/spatial.hpp), with s = R_b a its world axis and
// p_b the body origin (= the joint origin after motion):
//   revolute S = (s, p_b × s),   prismatic S = (0, s).
#pragma once
#include "core/model.hpp"
#include "core/spatial.hpp"

namespace femdyn {

inline bool moves(const Joint& j) { return j.theta >= 0; }

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
