// Loop-closure constraints Φ(q) = 0 between two places on the mechanism (docs/loops.md).
//
// A loop is cut at one joint of the spanning tree (the tree of bodies and joints); the cut is
// closed again by a constraint between a place A on one body and a place B on another (or the
// world). Each place is a body point with axes: p_A, R_A in world. With d = p_A − p_B:
//   ball            Φ = d                                  (3; world axes)
//   ball in a plane Φ = E R_Bᵀ d,  E the two axes ⟂ n      (2; B's axes)
//   point on line   Φ = E R_Bᵀ d,  E the two axes ⟂ the line direction (2)
//   point on plane  Φ = nᵀ R_Bᵀ d                          (1)
//   weld            Φ = (d, log(R_Bᵀ R_A))                 (6; the rotation vector in world axes)
//   distance        Φ = |d| − L                            (1; λ is the rod's tension)
//   gear            Φ = θ_j − Σ_i r_i θ_i − θ₀              (1; 1-DOF joint coordinates)
// The constrained equations (core/loops/constrained_dynamics.hpp) are
//   M^s q̈ + h = Q + Φ_qᵀ λ,    Φ_q q̈ = −Φ̇_q v,
// Φ_q the constraint Jacobian on the rates v and Φ̇_q v its bias (the q̈ = 0 part of Φ̈).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "core/model/attachment.hpp"

namespace femdyn {

enum class ConstraintType { Ball, Weld, Distance, PointOnLine, PointOnPlane, Gear };

struct LoopConstraint {
  std::string name;
  ConstraintType type = ConstraintType::Ball;
  Attachment a, b;
  // Ball in a plane, point on line, point on plane: the rows of E (unit, B's axes), one per
  // equation. A ball in space and the weld use world axes and leave E empty.
  std::vector<Vec3> axes;
  double length = 0;  // distance
  // gear: Φ = θ[joint] − Σ ratio θ[term] − offset, on the entries of θ (idx_q) of 1-DOF joints.
  int joint = -1;
  std::vector<std::pair<int, double>> terms;
  double offset = 0;
  VecX gear_rate;  // gear: its constant Jacobian row (e_j − Σ r_i e_i)ᵀ C on v (n)
  std::string where;
  int rows() const;  // the number of equations
};

const char* constraint_type_name(ConstraintType type);  // "ball", "weld", …
bool parse_constraint_type(const std::string& text, ConstraintType& type);

}  // namespace femdyn
