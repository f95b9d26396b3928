// Physical consistency of rigid-body mass properties, and the equimomental point masses.
#pragma once
#include <array>
#include <optional>
#include <string>

#include "core/spatial/math.hpp"

namespace femdyn {

// Empty when I (about the centre of mass) is physical: symmetric, principal moments >= 0 and
// satisfying the triangle inequality I1 + I2 >= I3. Otherwise what is wrong. Tolerances are
// relative to the larger of |I| and `reference` (e.g. the inertia I was computed from by the
// parallel-axis theorem, whose round-off it carries).
std::optional<std::string> inertia_problem(const Mat3& I, double reference = 0);

// Pseudo-inertia P = ∫[r;1][r;1]ᵀ dm = [[Σ, m c],[m cᵀ, m]], Σ = ½ tr(I_c) 1 − I_c + m c cᵀ.
Eigen::Matrix4d pseudo_inertia(double mass, const Vec3& com, const Mat3& I_com);

// Four equal point masses m/4 with the same pseudo-inertia (P must be positive definite):
// P = L Lᵀ, a Householder H maps L's last row onto equal entries, the columns of L Hᵀ divided
// by their last entry are the points. Empty when P is only semi-definite.
std::optional<std::array<Vec3, 4>> equimomental_points(double mass, const Vec3& com,
                                                       const Mat3& I_com);

}  // namespace femdyn
