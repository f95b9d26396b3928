// The equivalent element (the paper's "equivalent unit"): lumped inertia at nodes of one body.
//
// An element lives on one rigid body. It declares its nodes (positions in the body frame) and,
// per node, which of the six local DOFs it uses, in the order
//     x y z   (translation of the node, world axes)
//     rx ry rz (rotation rate of the body, body axes — a quasi-velocity, see docs/notation.md)
// Its local lumped mass m_e (6k x 6k for k nodes) is constant in these coordinates, and its
// velocity force g_e(u̇_e, u̇_e) (the gyroscopic term of a rotary inertia) is a bilinear form.
// Elements never see system indices: core owns the correlation table N_m and scatters.
#pragma once
#include <array>
#include <span>
#include <string_view>

#include "core/spatial/math.hpp"

namespace femdyn {

constexpr int kNodeDofs = 6;  // x y z rx ry rz

struct ElementNode {
  Vec3 position;                     // in the body frame
  std::array<bool, kNodeDofs> uses;  // which local DOFs this element uses at the node
};

// Mass properties about the body origin, expressed in the body frame.
struct MassProperties {
  double mass = 0;
  Vec3 com = Vec3::Zero();             // centre of mass
  Mat3 inertia_origin = Mat3::Zero();  // inertia tensor about the body origin
  Mat3 inertia_com() const;            // inertia tensor about the centre of mass
};

class Element {
 public:
  virtual ~Element() = default;
  virtual std::string_view type_name() const = 0;
  virtual std::span<const ElementNode> nodes() const = 0;

  // m_e, 6k x 6k, ordered node by node as (x y z rx ry rz).
  virtual MatX local_mass() const = 0;

  // Adds g_e(x, y) to g. x, y, g are local DOF vectors (6k). The element's velocity force is
  // g_e(u̇_e, u̇_e); for a rotary inertia J it is ω × (J ω). Default: no velocity force.
  virtual bool has_velocity_force() const { return false; }
  virtual void add_velocity_force(const Eigen::Ref<const VecX>& /*x*/,
                                  const Eigen::Ref<const VecX>& /*y*/,
                                  Eigen::Ref<VecX> /*g*/) const {}

  int local_dof_count() const { return kNodeDofs * static_cast<int>(nodes().size()); }

  // Rigid-body mass properties the element is equivalent to, from m_e alone:
  // the spatial inertia Xᵀ m_e X with X mapping a body twist (ω, v) to local DOF rates.
  MassProperties mass_properties() const;
};

// Gyroscopic bilinear form shared by rotary inertias: g += x_ω × (J y_ω).
void add_gyroscopic(const Mat3& J, const Vec3& x_omega, const Vec3& y_omega,
                    Eigen::Ref<VecX> g_rot3);

}  // namespace femdyn
