#include "core/dynamics/equations.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/dynamics/articulated.hpp"
#include "core/dynamics/body_inertia.hpp"
#include "core/dynamics/coupled_dynamics.hpp"
#include "core/dynamics/coupling_chain.hpp"
#include "core/dynamics/newton_euler.hpp"
#include "core/dynamics/span_inertia.hpp"
#include "core/dynamics/springs.hpp"
#include "core/joints/kernel.hpp"
#include "core/joints/passive.hpp"
#include "core/joints/rotor.hpp"
#include "core/kinematics/coupling.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/model/arguments.hpp"
#include "core/workspace/mass_solver.hpp"

namespace femdyn {
namespace {

// nodal += g(x, y): element velocity forces, gathered and scattered through N_m.
template <class X, class Y>
void add_velocity_forces(const Model& model, Workspace& ws, const X& x, const Y& y, VecX& nodal) {
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    const ElementEntry& E = model.elements[e];
    if (!E.element->has_velocity_force()) continue;
    VecX& xe = ws.local_x[e];
    VecX& ye = ws.local_y[e];
    VecX& ge = ws.local_g[e];
    // Gather x_e = N_mᵀ x, y_e = N_mᵀ y (a left-out DOF never moves: its rate is 0).
    for (std::size_t l = 0; l < E.table_row.size(); ++l) {
      const int i = E.table_row[l] - 1;
      xe[l] = i >= 0 ? x[i] : 0.0;
      ye[l] = i >= 0 ? y[i] : 0.0;
    }
    ge.setZero();
    E.element->add_velocity_force(xe, ye, ge);
    // Scatter g_e through N_m.
    for (std::size_t l = 0; l < E.table_row.size(); ++l)
      if (E.table_row[l]) nodal[E.table_row[l] - 1] += ge[l];
  }
}

// y = Tᵀ f (+ the body torques): after evaluate(), by the formed T where evaluate formed it
// (small models: one dense product is cheapest), otherwise by the backward sweep.
void generalized_force(const Model& model, Workspace& ws, const VecX& f, VecX& y,
                       bool with_torques) {
  if (model.mass_route == MassRoute::Composite) {
    apply_transpose(model, ws, f, y, with_torques ? 1.0 : 0.0);
    return;
  }
  if (!with_torques || model.torques.empty()) {
    y.noalias() = ws.T.transpose() * f;
    return;
  }
  ws.u_acc = f;  // + R_bᵀ τ on the body's rotation DOFs (body axes)
  for (const BodyTorque& t : model.torques) {
    const Vec3 tb = ws.body[t.body].R.transpose() * t.torque;
    for (int k = 0; k < 3; ++k)
      if (model.body_rot_dof[t.body][k] >= 0) ws.u_acc[model.body_rot_dof[t.body][k]] += tb[k];
  }
  y.noalias() = ws.T.transpose() * ws.u_acc;
}

// y += sign · Cᵀ(−k (θ − θ_rest) − c θ̇): joint springs and dampers act on θ; the coupling
// level maps them to q. Uses θ, θ̇ of the last propagate.
void add_joint_forces(const Model& model, const Workspace& ws, bool with_rates, double sign,
                      VecX& y) {
  for (int j = 0; j < model.n_theta(); ++j) {
    const Joint& J = model.bodies[model.theta_joint[j]].joint;
    if (J.nv != 1) continue;  // (springs, dampers, friction and stops: joints of one coordinate)
    const double f = passive_joint_force(J, ws.theta[J.idx_q], with_rates ? ws.theta_dot[j] : 0.0);
    if (f != 0) coupling_add_row(model, j, sign * f, y);
  }
}

// Q = Tᵀ F + Cᵀ(spring + damper) + τ, with F = F_constant + body torques.
void assemble_forces(const Model& model, Workspace& ws, const VecX& tau, bool with_rates) {
  if (model.has_nodal_forces)  // no gravity, no loads: no nodal forces to map
    generalized_force(model, ws, model.F_constant, ws.Q, true);
  else
    ws.Q.setZero();
  add_joint_forces(model, ws, with_rates, 1.0, ws.Q);
  if (tau.size() == ws.Q.size()) ws.Q += tau;
}

bool is_zero(const VecX& v) { return v.size() == 0 || v.cwiseAbs().maxCoeff() == 0.0; }

// ws.Ms from the body poses (composite route) or from T (transform route), both already
// propagated; mirrored so that it is symmetric in floating point too.
void form_mass_matrix(const Model& model, Workspace& ws) {
  if (model.mass_route == MassRoute::Composite) {
    composite_mass(model, ws);  // M^s by composite inertias; T is not formed
    return;
  }
  if (ws.Ms.rows() != model.n()) ws.Ms.setZero(model.n(), model.n());  // first use only
  // M^s = Tᵀ (M T)
  if (ws.MT.rows() != ws.T.rows() || ws.MT.cols() != ws.T.cols())
    ws.MT.resize(ws.T.rows(), ws.T.cols());  // first use only
  ws.MT.noalias() = model.M * ws.T;
  ws.Ms.noalias() = ws.T.transpose() * ws.MT;
  mirror_upper(ws.Ms);
  if (model.has_armature) ws.Ms += model.armature_mass;  // + Cᵀ diag(I_a G²) C
}

// M^s alone: the body poses (composite) or T (transform), then form_mass_matrix.
void mass_matrix_levels(const Model& model, Workspace& ws, const VecX& q) {
  const bool composite = model.mass_route == MassRoute::Composite;
  propagate(model, ws, q, q, {.jacobian = !composite, .bias = false, .rows = !composite});
  form_mass_matrix(model, ws);
}

// M^s, h and Q by the model's mass and force routes.
void evaluate_levels(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                     const VecX& tau) {
  const bool moving = !is_zero(qd);
  // The composite route needs only the body poses; the transform route the rows of T. The
  // body-level force route computes h by Newton–Euler, which leaves the poses.
  const bool composite = model.mass_route == MassRoute::Composite;
  const bool by_bodies = model.force_route == ForceRoute::Bodies;
  if (by_bodies && moving) newton_euler(model, ws, q, qd, nullptr, false, ws.h);
  if (!(by_bodies && moving && composite))
    propagate(model, ws, q, qd,
              {.jacobian = !composite, .bias = moving && !by_bodies, .rows = !composite});
  if (!moving) ws.theta_dot.setZero();

  form_mass_matrix(model, ws);

  // h = Tᵀ (M T'[q̇,q̇] + g(u̇,u̇)); zero at rest.
  if (!moving) {
    ws.h.setZero();
  } else if (!by_bodies) {
    ws.nodal.noalias() = model.M * ws.bias;
    if (model.has_velocity_forces) add_velocity_forces(model, ws, ws.u_dot, ws.u_dot, ws.nodal);
    generalized_force(model, ws, ws.nodal, ws.h, false);
  }
  assemble_forces(model, ws, tau, moving);
}

// h by Newton–Euler over the body inertias (ForceRoute::Bodies).
void bias_by_bodies(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  if (is_zero(qd)) {
    ws.h.setZero();
    return;
  }
  newton_euler(model, ws, q, qd, nullptr, false, ws.h);
}

// h by the node-level sweeps (ForceRoute::Nodes).
void bias_by_nodes(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  if (is_zero(qd)) {
    ws.h.setZero();
    return;
  }
  propagate(model, ws, q, qd, {.jacobian = false, .bias = true});
  ws.nodal.noalias() = model.M * ws.bias;
  if (model.has_velocity_forces) add_velocity_forces(model, ws, ws.u_dot, ws.u_dot, ws.nodal);
  apply_transpose(model, ws, ws.nodal, ws.h);  // h = Tᵀ (M T'[q̇,q̇] + g), T not formed
}

// q̈ by evaluate(), then the Cholesky factorisation of M^s (DynamicsRoute::Cholesky).
Status forward_by_cholesky(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                           const VecX& tau) {
  model.routes.evaluate(model, ws, q, qd, tau);  // (τ holds the springs' Q_s already)
  Status st = ws.solver.factorize(ws.Ms);
  if (st.ok) {
    ws.qdd = ws.Q - ws.h;
    ws.solver.solve_in_place(ws.qdd);
  }
  return st;
}

// τ by body-level Newton–Euler (ForceRoute::Bodies).
void inverse_by_bodies(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                       const VecX& qdd) {
  newton_euler(model, ws, q, qd, &qdd, true, ws.tau);
  add_joint_forces(model, ws, true, -1.0, ws.tau);
  if (model.has_armature) ws.tau.noalias() += model.armature_mass * qdd;  // rotors: M_a q̈
}

// τ = M^s q̈ + h − Q(τ = 0) = Tᵀ (M (T q̈ + T'[q̇,q̇]) + g(u̇,u̇) − F) − Cᵀ(spring + damper),
// by two kinematic sweeps and one sweep of Tᵀ (ForceRoute::Nodes): O(N_u + bodies), neither T
// nor M^s formed.
void inverse_by_nodes(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                      const VecX& qdd) {
  propagate(model, ws, q, qdd, {.jacobian = false, .bias = true});
  ws.u_acc = ws.u_dot;  // T q̈
  propagate(model, ws, q, qd, {.jacobian = false, .bias = true});
  ws.u_acc += ws.bias;  // + T'[q̇,q̇]
  ws.nodal.noalias() = model.M * ws.u_acc;
  if (model.has_velocity_forces && !is_zero(qd))
    add_velocity_forces(model, ws, ws.u_dot, ws.u_dot, ws.nodal);
  if (model.has_nodal_forces) ws.nodal -= model.F_constant;
  apply_transpose(model, ws, ws.nodal, ws.tau, model.has_nodal_forces ? -1.0 : 0.0);
  add_joint_forces(model, ws, true, -1.0, ws.tau);
  if (model.has_armature) ws.tau.noalias() += model.armature_mass * qdd;  // rotors: M_a q̈
}

std::vector<MatX> transform_hessian_levels(const Model& model, Workspace& ws, const VecX& q) {
  // T'_{·bc} = ∂T_{·b}/∂q_c = T'[e_b, e_c]: one bilinear sweep per pair.
  const int n = model.n(), N = model.n_u();
  std::vector<MatX> H(N, MatX::Zero(n, n));
  VecX eb = VecX::Zero(n), ec = VecX::Zero(n);
  for (int b = 0; b < n; ++b)
    for (int c = 0; c < n; ++c) {
      eb.setZero();
      ec.setZero();
      eb[b] = 1;
      ec[c] = 1;
      propagate_bilinear(model, ws, q, eb, ec, {.jacobian = false, .bias = true});
      for (int i = 0; i < N; ++i) H[i](b, c) = ws.bias[i];
    }
  return H;
}

std::vector<MatX> third_order_tensor_levels(const Model& model, Workspace& ws, const VecX& q) {
  const int n = model.n(), N = model.n_u();
  const std::vector<MatX> Tp = transform_hessian(model, ws, q);
  propagate(model, ws, q, VecX::Zero(n), {.jacobian = true, .bias = false});
  const MatX T = ws.T;
  std::vector<MatX> D(n, MatX::Zero(n, n));
  VecX col(N), nodal(N);
  for (int b = 0; b < n; ++b)
    for (int c = 0; c < n; ++c) {
      // (M T'_{·bc} + G_{·bc}),  G_{·bc} = g(T e_b, T e_c)
      for (int i = 0; i < N; ++i) col[i] = Tp[i](b, c);
      nodal = model.M * col;
      if (model.has_velocity_forces) add_velocity_forces(model, ws, T.col(b), T.col(c), nodal);
      const VecX Dbc = T.transpose() * nodal;
      for (int a = 0; a < n; ++a) D[a](b, c) = Dbc[a];
    }
  return D;
}

void joint_state_levels(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  coupling_configuration(model, q, ws.theta);
  coupling_apply(model, qd, ws.theta_dot);
}

Energy energy_levels(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  Energy E;
  if (model.mass_route == MassRoute::Composite) {
    // Body by body, ½ Σ_b V_bᵀ Λ_b V_b with V_b = J_b q̇ the body's twist in its own axes: the
    // same ½ q̇ᵀ M^s q̇ (M^s = Σ_b J_bᵀ Λ_b J_b, core/dynamics/body_inertia.hpp) in O(bodies),
    // without forming the n x n M^s.
    propagate(model, ws, q, qd, {.jacobian = false, .bias = true, .rows = false});
    for (std::size_t b = 0; b < model.bodies.size(); ++b) {
      const BodyState& B = ws.body[b];
      Vec6 V;
      V << B.R.transpose() * B.w, B.R.transpose() * B.v;
      E.kinetic += 0.5 * V.dot(model.body_inertia[b] * V);
    }
    E.kinetic += span_kinetic_energy(model, ws);
    if (model.has_armature)  // the rotors: ½ Σ I_a G² θ̇² (the other route has them in M^s)
      for (int j = 0; j < model.n_theta(); ++j)
        E.kinetic += 0.5 * model.bodies[model.theta_joint[j]].joint.reflected_inertia *
                     ws.theta_dot[j] * ws.theta_dot[j];
  } else {
    evaluate(model, ws, q, qd, VecX());
    E.kinetic = 0.5 * qd.dot(ws.Ms.lazyProduct(qd));  // (no temporary: looked at mid-run)
  }
  // Potential of constant nodal forces: −F_i x_i over translation DOFs (x_i = o + the node's
  // place from the reference point o: the world position).
  for (int i = 0; i < model.n_u(); ++i) {
    const SystemDof& d = model.dofs[i];
    if (d.kind != DofKind::Translation || model.F_constant[i] == 0) continue;
    const SystemNode& node = model.nodes[d.carrier];
    const BodyState& B = ws.body[node.body];
    E.potential -= model.F_constant[i] * (ws.origin + (B.p + B.R * node.r))[d.axis];
  }
  for (int j = 0; j < model.n_theta(); ++j) {
    const Joint& J = model.bodies[model.theta_joint[j]].joint;
    if (J.nv == 1) E.potential += passive_joint_potential(J, ws.theta[J.idx_q]);
  }
  return E;
}

// The spherical and free joints' velocity terms, out of the hot path of every other model: the
// free rotors' h_a (core/joints/rotor.hpp) into `h`, times `sign_h`, and the dampers' −c θ̇ and
// the flexible bars' −D q̇ (core/joints/passive.hpp) into `Q`, times `sign_Q`.
bool has_rate_terms(const Model& m) {
  return !m.free_rotors.empty() || !m.rate_dampers.empty() || m.has_rate_damping;
}
[[gnu::noinline]] void add_rate_terms(const Model& m, const VecX& qd, VecX& h, VecX& Q,
                                      double sign_h = 1.0, double sign_Q = 1.0) {
  add_rotor_bias(m, qd, sign_h, h);
  add_rate_dampers(m, qd, sign_Q, Q);
  if (m.has_rate_damping) add_rate_damping(m, qd, sign_Q, Q);
}

}  // namespace

EquationRoutes choose_equation_routes(const Model& model) {
  EquationRoutes r;
  if (model.coupling_level) {  // the law chain: the tree's equations reduced through θ = g(q)
    r.evaluate = chain::evaluate;
    r.mass_matrix = chain::mass_matrix;
    const Model& tree = *model.tree;
    const bool tree_by_bodies = tree.force_route == ForceRoute::Bodies;
    r.evaluate_bias = tree_by_bodies ? chain::evaluate_bias_by_bodies : chain::evaluate_bias;
    r.forward_dynamics = tree_by_bodies && tree.mass_route == MassRoute::Composite
                             ? chain::forward_dynamics_by_bodies
                             : chain::forward_dynamics;
    r.inverse_dynamics = chain::inverse_dynamics;
    r.transform_hessian = chain::transform_hessian;
    r.third_order_tensor = chain::third_order_tensor;
    r.energy = chain::energy;
    r.joint_state = chain::joint_state;
    r.propagate_bilinear = chain::propagate_bilinear;
    r.names = {"the tree's M_θ through the coupling law: Gᵀ M_θ G, G = ∂θ/∂q",
               tree_by_bodies ? "the tree's recursive Newton–Euler through the coupling law"
                              : "the tree's node sweeps through the coupling law",
               r.forward_dynamics == chain::forward_dynamics_by_bodies
                   ? "joint-space sweeps through the coupling law, then Cholesky"
                   : "the equations through the coupling law, then Cholesky"};
    return r;
  }
  r.evaluate = evaluate_levels;
  r.mass_matrix = mass_matrix_levels;
  r.transform_hessian = transform_hessian_levels;
  r.third_order_tensor = third_order_tensor_levels;
  r.energy = energy_levels;
  r.joint_state = joint_state_levels;
  r.propagate_bilinear = propagate_bilinear_levels;
  const bool by_bodies = model.force_route == ForceRoute::Bodies;
  r.evaluate_bias = by_bodies ? bias_by_bodies : bias_by_nodes;
  r.inverse_dynamics = by_bodies ? inverse_by_bodies : inverse_by_nodes;
  r.names.mass = model.mass_route == MassRoute::Composite ? "composite body inertias"
                                                          : "Tᵀ M T (the transform T)";
  r.names.force = by_bodies ? "recursive Newton–Euler over the bodies" : "node sweeps (Tᵀ, T')";
  if (model.dynamics_route == DynamicsRoute::Articulated) {
    r.forward_dynamics = articulated_forward_dynamics;
    r.names.forward = "articulated bodies";
  } else if (by_bodies && model.mass_route == MassRoute::Composite &&
             model.spanning_masses.empty()) {
    r.forward_dynamics = coupled_forward_dynamics;
    r.names.forward = "joint-space sweeps, then Cholesky";
  } else {
    r.forward_dynamics = forward_by_cholesky;
    r.names.forward = "the equations, then Cholesky";
  }
  return r;
}

// Each function of equations.hpp: the model's route (Model::routes), chosen once by compile().

void mass_matrix(const Model& model, Workspace& ws, const VecX& q) {
  require_state(model, "mass_matrix", q);
  model.routes.mass_matrix(model, ws, q);
}

// Two-point springs (core/dynamics/springs.hpp) act on every route as a generalized force Q_s added
// to τ.

void evaluate(const Model& model, Workspace& ws, const VecX& q, const VecX& qd, const VecX& tau) {
  require_state(model, "evaluate", q, &qd, "qd");
  require_size(model, "evaluate", "tau", tau, ArgumentKind::Actuation);
  model.routes.evaluate(model, ws, q, qd, tau);
  if (has_rate_terms(model)) add_rate_terms(model, qd, ws.h, ws.Q);
  if (model.springs.empty()) return;
  spring_forces(model, ws, q, qd);
  ws.Q += ws.Q_springs;
}

void evaluate_bias(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  require_state(model, "evaluate_bias", q, &qd, "qd");
  model.routes.evaluate_bias(model, ws, q, qd);
  if (!model.free_rotors.empty()) add_rotor_bias(model, qd, 1.0, ws.h);
}

namespace {

// The spanning tree's q̈ by the model's route, the arguments checked. The springs' Q_s, the
// spherical and free joints' dampers and the free rotors' −h_a are applied forces to every
// route's q̈ (the last two depend on q̇ alone).
Status tree_accelerations(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                          const VecX& tau) {
  const VecX* applied = &tau;
  if (!model.springs.empty() || has_rate_terms(model)) {
    if (!model.springs.empty()) {
      spring_forces(model, ws, q, qd);
      ws.tau_applied = ws.Q_springs;
    } else {
      ws.tau_applied.setZero(model.n());
    }
    if (tau.size()) ws.tau_applied += tau;  // (none: no actuation)
    if (has_rate_terms(model)) add_rate_terms(model, qd, ws.tau_applied, ws.tau_applied, -1.0);
    applied = &ws.tau_applied;
  }
  const Status st = model.routes.forward_dynamics(model, ws, q, qd, *applied);
  if (!st.ok) return st;
  return finite_accelerations(model, ws.qdd);
}

}  // namespace

Status tree_forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                             const VecX& tau) {
  require_state(model, "tree_forward_dynamics", q, &qd, "qd");
  require_size(model, "tree_forward_dynamics", "tau", tau, ArgumentKind::Actuation);
  return tree_accelerations(model, ws, q, qd, tau);
}

Status forward_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                        const VecX& tau) {
  require_state(model, "forward_dynamics", q, &qd, "qd");
  require_size(model, "forward_dynamics", "tau", tau, ArgumentKind::Actuation);
  if (!model.constraints.empty())
    throw ArgumentError("forward_dynamics: the model '" + model.name + "' has closed loops (" +
                        std::to_string(model.constraint_rows) +
                        " constraint equations): its q̈ is mechanism_forward_dynamics' (with a "
                        "LoopWorkspace, core/loops/constrained_dynamics.hpp); the spanning "
                        "tree's, loops ignored, is tree_forward_dynamics'");
  return tree_accelerations(model, ws, q, qd, tau);
}

Status finite_accelerations(const Model& model, const VecX& qdd) {
  for (Eigen::Index a = 0; a < qdd.size(); ++a)
    if (!std::isfinite(qdd[a]))
      return {false,
              "q̈ of '" + model.coordinate_names[a] +
                  "' is NaN or Inf (the forces or the state overflow double precision)",
              static_cast<int>(a), true};
  return {};
}

void inverse_dynamics(const Model& model, Workspace& ws, const VecX& q, const VecX& qd,
                      const VecX& qdd) {
  require_state(model, "inverse_dynamics", q, &qd, "qd");
  require_size(model, "inverse_dynamics", "qdd", qdd, ArgumentKind::Rate);
  model.routes.inverse_dynamics(model, ws, q, qd, qdd);
  if (has_rate_terms(model)) add_rate_terms(model, qd, ws.tau, ws.tau, 1.0, -1.0);
  if (model.springs.empty()) return;
  spring_forces(model, ws, q, qd);
  ws.tau -= ws.Q_springs;
}

std::vector<MatX> transform_hessian(const Model& model, Workspace& ws, const VecX& q) {
  require_state(model, "transform_hessian", q);
  return model.routes.transform_hessian(model, ws, q);
}

std::vector<MatX> third_order_tensor(const Model& model, Workspace& ws, const VecX& q) {
  require_state(model, "third_order_tensor", q);
  std::vector<MatX> D = model.routes.third_order_tensor(model, ws, q);
  add_rotor_bias_tensor(model, D);
  return D;
}

void joint_state(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  require_state(model, "joint_state", q, &qd, "qd");
  model.routes.joint_state(model, ws, q, qd);
}

Energy energy(const Model& model, Workspace& ws, const VecX& q, const VecX& qd) {
  require_state(model, "energy", q, &qd, "qd");
  Energy E = model.routes.energy(model, ws, q, qd);
  if (!model.springs.empty()) E.potential += spring_potential(model, ws, q);
  return E;
}

std::vector<std::pair<std::string, std::string>> RouteReport::fields() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [key, name] : {std::pair<const char*, const std::string*>{"mass", &mass},
                                  {"force", &force},
                                  {"forward_dynamics", &forward},
                                  {"solver", &solver},
                                  {"loops", &loops}})
    if (!name->empty()) out.emplace_back(key, *name);
  return out;
}

RouteReport route_report(const Model& model) {
  const RouteNames& names = model.routes.names;
  RouteReport r{names.mass, names.force, names.forward, "", ""};
  if (model.routes.forward_dynamics != articulated_forward_dynamics)
    switch (model.mass_pattern.solver) {
      case SolverKind::Dense:
        r.solver = "dense Cholesky (LLᵀ)";
        break;
      case SolverKind::Sparse:
        r.solver = "sparse Cholesky (CHOLMOD)";
        break;
      case SolverKind::Tree:
        r.solver = "the coordinate tree's LTDL";
        break;
    }
  if (!model.constraints.empty()) r.loops = names.mechanism;
  return r;
}

}  // namespace femdyn
