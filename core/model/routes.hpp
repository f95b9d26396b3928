// EquationRoutes: how one model's equations are computed, chosen once by compile() from the facts
// it checked (choose_routes, compile/routes.hpp): a model with a nonlinear coupling law
// takes the law chain (core/dynamics/coupling_chain.hpp) for every function; any other model the
// routes of Model::mass_route, force_route and dynamics_route. Each function of
// core/dynamics/equations.hpp, and propagate_bilinear (core/kinematics/kinematics.hpp), calls
// through this table: no algorithm recombines the route enums or asks for the coupling level per
// call.
#pragma once
#include <vector>

#include "core/spatial/math.hpp"

namespace femdyn {

struct Model;
struct Workspace;
struct Status;
struct Energy;
struct KinematicsRequest;
struct LoopWorkspace;

// What each route is, named where choose_equation_routes chooses it, so that reports say which
// one ran (route_report, core/dynamics/equations.hpp).
struct RouteNames {
  const char* mass = "";       // M^s
  const char* force = "";      // h and τ
  const char* forward = "";    // the tree's q̈
  const char* mechanism = "";  // the mechanism's q̈: the tree's, or the constrained one on loops
};

struct EquationRoutes {
  void (*evaluate)(const Model&, Workspace&, const VecX& q, const VecX& qd,
                   const VecX& tau) = nullptr;
  void (*mass_matrix)(const Model&, Workspace&, const VecX& q) = nullptr;
  void (*evaluate_bias)(const Model&, Workspace&, const VecX& q, const VecX& qd) = nullptr;
  Status (*forward_dynamics)(const Model&, Workspace&, const VecX& q, const VecX& qd,
                             const VecX& tau) = nullptr;
  void (*inverse_dynamics)(const Model&, Workspace&, const VecX& q, const VecX& qd,
                           const VecX& qdd) = nullptr;
  std::vector<MatX> (*transform_hessian)(const Model&, Workspace&, const VecX& q) = nullptr;
  std::vector<MatX> (*third_order_tensor)(const Model&, Workspace&, const VecX& q) = nullptr;
  Energy (*energy)(const Model&, Workspace&, const VecX& q, const VecX& qd) = nullptr;
  void (*joint_state)(const Model&, Workspace&, const VecX& q, const VecX& qd) = nullptr;
  void (*propagate_bilinear)(const Model&, Workspace&, const VecX& q, const VecX& x, const VecX& y,
                             KinematicsRequest request) = nullptr;
  // q̈ of the mechanism (mechanism_forward_dynamics, core/loops/constrained_dynamics.hpp): the
  // tree's forward_dynamics, or on a model with loops the constrained equations (its
  // LoopWorkspace given). Chosen by compile's choose_routes, which alone sees both.
  Status (*mechanism_forward_dynamics)(const Model&, Workspace&, LoopWorkspace*, const VecX& q,
                                       const VecX& v, const VecX& tau) = nullptr;
  RouteNames names;
};

// The table for `model`, from its route enums and coupling level (core/dynamics/equations.cpp).
// compile() stores it in Model::routes once those are final.
EquationRoutes choose_equation_routes(const Model& model);

}  // namespace femdyn
