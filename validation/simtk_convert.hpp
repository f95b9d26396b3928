// femdyn's Eigen vectors and rotations as Simbody's, and back (the Simbody twin's files).
// A rotation handed over is orthonormal: the model's frames, attachments and joint origins are
// built from rpy or from unit axes.
#pragma once
#include <Simbody.h>

#include "core/spatial/math.hpp"

namespace femdyn::validation {

inline SimTK::Vec3 to_simtk(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

inline SimTK::Rotation to_simtk(const Mat3& R) {
  SimTK::Mat33 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  return SimTK::Rotation(m, true);
}

inline Vec3 from_simtk(const SimTK::Vec3& v) { return {v[0], v[1], v[2]}; }

inline Mat3 from_simtk(const SimTK::Mat33& m) {
  Mat3 out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out(i, j) = m(i, j);
  return out;
}

}  // namespace femdyn::validation
