// Spatial (6D) vectors in world axes about the world origin (Featherstone, "Rigid Body Dynamics
// Algorithms", ch. 2): a motion vector is (ω, v_O), v_O the velocity of the body-fixed point at
// the world origin; a force vector is (n_O, f), n_O the moment about the origin. Expressed this
// way no coordinate transform is needed between bodies (the book's "base coordinates").
// "The origin" in the recursions is the workspace's reference point o (Workspace::origin), the
// first body's origin, from which every body place is measured: the sums below then hold
// entries of the mechanism's own size (m·|p|², |p| its extent) wherever it is in the world.
#pragma once
#include <Eigen/Dense>

#include "core/spatial/math.hpp"

namespace femdyn {

using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec6 = Eigen::Matrix<double, 6, 1>;

// a × b for motion vectors: (ω_a × ω_b, ω_a × v_b + v_a × ω_b). These small products are
// always inlined: the recursions call them per body, and a call costs as much as the product.
[[gnu::always_inline]] inline Vec6 cross_motion(const Vec6& a, const Vec6& b) {
  Vec6 r;
  r.head<3>() = cross3(a.head<3>(), b.head<3>());
  r.tail<3>() = cross3(a.head<3>(), b.tail<3>()) + cross3(a.tail<3>(), b.head<3>());
  return r;
}

// a ×* f for a motion a and a force f = (n, f): (ω × n + v × f, ω × f).
[[gnu::always_inline]] inline Vec6 cross_force(const Vec6& a, const Vec6& f) {
  Vec6 r;
  r.head<3>() = cross3(a.head<3>(), f.head<3>()) + cross3(a.tail<3>(), f.tail<3>());
  r.tail<3>() = cross3(a.head<3>(), f.tail<3>());
  return r;
}

// The wrench (n_O, f) about the world origin of a force f at the world point x.
inline Vec6 wrench_at_origin(const Vec3& x, const Vec3& f) {
  Vec6 w;
  w << x.cross(f), f;
  return w;
}

// A rigid body's spatial inertia in the body frame about the body origin, twist (ω, v):
//   Λ = [[I, [h]×], [[h]×ᵀ, m 1]],   m the mass, h = m c the first moment, I the inertia tensor
// about the origin. Three numbers instead of 36: moving it costs a rotation of I and a few
// outer products (Pinocchio stores its inertias the same way).
struct RigidInertia {
  double m = 0;
  Vec3 h = Vec3::Zero();
  Mat3 I = Mat3::Zero();

  Mat6 matrix() const {
    Mat6 L;
    L << I, skew(h), skew(h).transpose(), m * Mat3::Identity();
    return L;
  }
  // Λ v = (I ω + h × v, m v − h × ω): 30 operations instead of the 6 × 6 product.
  [[gnu::always_inline]] Vec6 operator*(const Vec6& v) const {
    Vec6 f;
    f.head<3>().noalias() = I * v.head<3>();
    f.head<3>() += cross3(h, v.tail<3>());
    f.tail<3>() = m * v.tail<3>() - cross3(h, v.head<3>());
    return f;
  }
  // A sum of rigid inertias about one point is one: the composites stay in this form.
  RigidInertia& operator+=(const RigidInertia& o) {
    m += o.m;
    h += o.h;
    I += o.I;
    return *this;
  }
};

// The same inertia about the world origin, world axes, for body orientation R and origin p:
// Λ^O = Xᵀ Λ^w X with X = [[1, 0], [−[p]×, 1]] (X maps (ω, v_O) to (ω, v_p = v_O + ω × p)):
//   h_w = R h,   h' = h_w + m p,
//   I' = R I Rᵀ − [h_w]×[p]× − [p]×[h_w]× − m [p]×[p]×
//      = R I Rᵀ − (p h_wᵀ + h_w pᵀ) + 2 (h_w·p) 1 − m (p pᵀ − |p|² 1),
//   Λ^O = [[I', [h']×], [[h']×ᵀ, m 1]].
inline RigidInertia inertia_at_origin(const RigidInertia& L, const Mat3& R, const Vec3& p) {
  RigidInertia O;
  const Vec3 hw = R * L.h;
  O.m = L.m;
  O.h = hw + L.m * p;
  O.I.noalias() = R * L.I * R.transpose();
  O.I.noalias() -= p * hw.transpose() + hw * p.transpose() + L.m * p * p.transpose();
  O.I.diagonal().array() += 2 * hw.dot(p) + L.m * p.squaredNorm();
  return O;
}

}  // namespace femdyn
