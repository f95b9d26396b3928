// A place fixed on a body, where a loop constraint (core/model/loop_constraint.hpp) or a two-point
// spring (core/dynamics/springs.hpp) attaches: origin p and axes R in the body frame; body −1 is
// the world. Its motion is attachment_motion (core/kinematics/frames.hpp).
#pragma once
#include <string>

#include "core/spatial/math.hpp"

namespace femdyn {

struct Attachment {
  int body = -1;
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero();
  std::string name;  // the frame or body it names, for messages
};

// Its motion, world axes (attachment_motion).
struct AttachmentMotion {
  Mat3 R = Mat3::Identity();
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), w = Vec3::Zero();
  Vec3 a = Vec3::Zero(), alpha = Vec3::Zero();  // the q̈ = 0 accelerations
  MatX Jv, Jw;                                  // 3 × n (with `jacobian`)
};

}  // namespace femdyn
