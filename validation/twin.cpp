// The Simbody twin (twin.hpp). Compiled without NDEBUG: Debian's Simbody 3.7 is built without
// it and some of its header classes change layout with it (see CMakeLists.txt).
#include "validation/twin.hpp"

#include <Simbody.h>
#include <dlfcn.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "core/names.hpp"
#include "validation/twin_loops.hpp"

namespace femdyn::validation {

namespace {

SimTK::Vec3 to_simtk(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

SimTK::Rotation to_simtk(const Mat3& R) {
  SimTK::Mat33 m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = R(i, j);
  return SimTK::Rotation(m, true);  // R is orthonormal (built from rpy)
}

// The integrator `which` on `system`, in its default error-controlled (variable-step) mode.
std::unique_ptr<SimTK::Integrator> make_integrator(SimbodyIntegrator which,
                                                   const SimTK::System& system) {
  switch (which) {
    case SimbodyIntegrator::RungeKuttaMerson:
      return std::make_unique<SimTK::RungeKuttaMersonIntegrator>(system);
    case SimbodyIntegrator::RungeKutta3:
      return std::make_unique<SimTK::RungeKutta3Integrator>(system);
    case SimbodyIntegrator::RungeKuttaFeldberg:
      return std::make_unique<SimTK::RungeKuttaFeldbergIntegrator>(system);
    case SimbodyIntegrator::Verlet:  // the constructor without a step size: variable step
      return std::make_unique<SimTK::VerletIntegrator>(system);
    case SimbodyIntegrator::SemiExplicitEuler2:
      return std::make_unique<SimTK::SemiExplicitEuler2Integrator>(system);
    case SimbodyIntegrator::CPodes:  // the constructor's default: BDF with Newton iteration
      return std::make_unique<SimTK::CPodesIntegrator>(system);
  }
  throw std::invalid_argument("unknown SimbodyIntegrator");
}

// The file of the library the dynamic linker binds `symbol` to for the whole process, or "".
std::string defining_library(const char* symbol) {
  void* address = dlsym(RTLD_DEFAULT, symbol);
  Dl_info info;
  if (!address || !dladdr(address, &info) || !info.dli_fname) return {};
  return info.dli_fname;
}

// Why CPodes cannot run in this process, or "". Simbody's CPodes is its own copy of SUNDIALS
// CVODES, which exports the SUNDIALS names (N_VSpace, N_VClone, DenseGETRF, ...) unprefixed.
// A process that also exports the system's SUNDIALS (femdyn_core links it statically and keeps
// its symbols out of the dynamic table, see CMakeLists.txt, so femdyn's do not) binds each
// such name once, to whichever library comes first; if that is not Simbody's,
// CPodes calls SUNDIALS 6 on its own vectors and aborts in an assert (nvector_SimTK.h) — not
// an exception, so it must be refused before it starts. Checked once per process.
const std::string& cpodes_conflict() {
  static const std::string why = [] {
    const std::string simbody = defining_library("CPodeCreate");  // only in libSimTKmath
    for (const char* name :
         {"N_VSpace", "N_VClone", "N_VLinearSum", "N_VWrmsNorm", "DenseGETRF", "newDenseMat"}) {
      const std::string where = defining_library(name);
      if (!simbody.empty() && where == simbody) continue;
      return std::string("CPodes cannot run in this process: its SUNDIALS symbol ") + name +
             " binds to " + (where.empty() ? std::string("nothing") : where) +
             ", not to Simbody's " + (simbody.empty() ? std::string("libSimTKmath") : simbody) +
             " (the system SUNDIALS linked by femdyn shadows Simbody's bundled copy)";
    }
    return std::string();
  }();
  return why;
}

// A message on one line: its lines joined by spaces, without SimTK's "SimTK Exception thrown
// at file:line:" headers. (The first line alone would often be such a header, or
// "Integrator step failed at time 0 apparently because:", with the cause on the next lines.)
std::string one_line(const std::string& text) {
  std::istringstream in(text);
  std::string out, line;
  while (std::getline(in, line)) {
    const auto begin = line.find_first_not_of(" \t\r");
    if (begin == std::string::npos) continue;
    const auto end = line.find_last_not_of(" \t\r");
    line = line.substr(begin, end + 1 - begin);
    if (line.rfind("SimTK Exception thrown at ", 0) == 0) continue;
    out += (out.empty() ? "" : " ") + line;
  }
  return out;
}

SimTK::MassProperties mass_properties(const TwinBody& p) {
  const Mat3& I = p.inertia_origin;  // Simbody wants the inertia about the body origin
  return SimTK::MassProperties(
      p.mass, to_simtk(p.com),
      SimTK::Inertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
}

}  // namespace

std::vector<int> independent_thetas(const TwinModel& model) {
  // Row j of C is e_k: its only stored non-zero is a 1 in column k (explicit zeros ignored).
  const int nt = model.n_theta(), n = model.n();
  std::vector<int> nonzeros(nt, 0), column(nt, -1);
  std::vector<double> value(nt, 0);
  for (int k = 0; k < model.C.outerSize(); ++k)
    for (SpMatX::InnerIterator it(model.C, k); it; ++it) {
      if (it.value() == 0) continue;
      const auto j = static_cast<std::size_t>(it.row());
      ++nonzeros[j], column[j] = k, value[j] = it.value();
    }
  std::vector<int> out(n, -1);
  for (int j = 0; j < nt; ++j)  // the first such θ_j, as the scan by rows found it
    if (model.theta0[j] == 0 && nonzeros[j] == 1 && value[j] == 1.0 && out[column[j]] < 0)
      out[column[j]] = j;
  return out;
}

int independent_theta(const TwinModel& model, int k) { return independent_thetas(model).at(k); }

constexpr bool kTiming = false;  // set_state's fit_rods in the timing entry points

struct SimbodyTwin::Impl {
  const TwinModel model;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter{system};
  SimTK::GeneralForceSubsystem forces{system};
  std::vector<SimTK::MobilizedBody> mobod;  // per femdyn body
  std::vector<SimTK::MobilizedBody> rods;   // closed loop: per TwinModel::rods
  VecX loop_theta, loop_theta_dot;          // closed loop: θ = g(q), θ̇ = G q̇
  std::vector<int> theta_q, theta_u;        // θ index -> Simbody q / u index
  std::vector<int> independent;             // q index -> θ index, -1 if none
  bool couplers = true;
  Eigen::SparseMatrix<double, Eigen::RowMajor> C_rows;  // C by rows: θ_j = Σ C_jk q_k + θ0_j
  SimTK::State state;
  SimTK::Matrix M_theta;
  SimTK::Vector zero_mobility, residual, mobility, udot;
  SimTK::Vector_<SimTK::SpatialVec> zero_body, A_GB;

  explicit Impl(TwinModel tm) : model(std::move(tm)), C_rows(model.C) {
    using namespace SimTK;
    const TwinModel& m = model;
    const int nb = static_cast<int>(m.bodies.size());
    mobod.reserve(nb);
    for (int b = 0; b < nb; ++b) {
      const TwinBody& j = m.bodies[b];
      try {
        add_body(j);
      } catch (const std::exception& e) {
        throw femdyn::Error("Simbody refuses body '" + escaped(j.name) +
                            "': " + one_line(e.what()));
      }
    }
    try {
      rods = loops::add_rods(m, mobod);
    } catch (const std::exception& e) {
      throw femdyn::Error("Simbody refuses a rod: " + one_line(e.what()));
    }
    finish_system();
  }

  // One femdyn body as a mobilized body with its mobilizer, spring and damper.
  void add_body(const TwinBody& j) {
    using namespace SimTK;
    {
      MobilizedBody& parent =
          j.parent < 0 ? static_cast<MobilizedBody&>(matter.updGround()) : mobod[j.parent];
      const SimTK::Body::Rigid rigid(mass_properties(j));
      const Rotation R_pj = to_simtk(j.R_pj);
      const SimTK::Vec3 p_pj = to_simtk(j.p_pj);
      switch (j.joint) {
        case TwinBody::Joint::Revolute: {
          const Rotation R_a(UnitVec3(to_simtk(j.axis)), ZAxis);  // Pin turns about z
          mobod.push_back(MobilizedBody::Pin(parent, Transform(R_pj * R_a, p_pj), rigid,
                                             Transform(R_a, SimTK::Vec3(0))));
          break;
        }
        case TwinBody::Joint::Prismatic: {
          const Rotation R_a(UnitVec3(to_simtk(j.axis)), XAxis);  // Slider moves along x
          mobod.push_back(MobilizedBody::Slider(parent, Transform(R_pj * R_a, p_pj), rigid,
                                                Transform(R_a, SimTK::Vec3(0))));
          break;
        }
        case TwinBody::Joint::Fixed:
          mobod.push_back(MobilizedBody::Weld(parent, Transform(R_pj, p_pj), rigid, Transform()));
          break;
      }
      if (j.theta >= 0) {
        if (j.stiffness != 0)
          Force::MobilityLinearSpring(forces, mobod.back(), MobilizerQIndex(0), j.stiffness,
                                      j.rest);
        if (j.damping != 0)
          Force::MobilityLinearDamper(forces, mobod.back(), MobilizerUIndex(0), j.damping);
      }
    }
  }

  // Gravity, loads and couplers, then the realized state.
  void finish_system() {
    using namespace SimTK;
    const TwinModel& m = model;
    if (m.gravity.norm() > 0)
      Force::Gravity(forces, matter, UnitVec3(to_simtk(m.gravity)), m.gravity.norm());
    for (const TwinModel::Load& l : m.loads) {
      if (!l.force.isZero(0))
        Force::ConstantForce(forces, mobod[l.body], to_simtk(l.point), to_simtk(l.force));
      if (!l.torque.isZero(0)) Force::ConstantTorque(forces, mobod[l.body], to_simtk(l.torque));
    }

    if (m.closed_loop()) {  // the laws and rods as constraints, pointwise and for trajectories
      independent = m.coordinate_theta;
      loops::add_constraints(matter, m, mobod, rods);
    } else {
      add_linear_couplers();
    }
    finish_state();
  }

  // Couplings θ_j = Σ_k C_jk q_k + θ0_j as constraints among the mobilities, for trajectories.
  void add_linear_couplers() {
    using namespace SimTK;
    const TwinModel& m = model;
    independent = independent_thetas(m);
    std::vector<bool> is_independent(m.n_theta(), false);
    for (int k = 0; k < m.n(); ++k) {
      if (independent[k] < 0)
        couplers = false;
      else
        is_independent[independent[k]] = true;
    }
    if (couplers) {
      for (int j = 0; j < m.n_theta(); ++j) {
        if (is_independent[j]) continue;
        // f(θ_j, θ_ind(k)...) = θ_j − Σ_k C_jk θ_ind(k) − θ0_j = 0
        std::vector<MobilizedBodyIndex> bodies{mobod[m.theta_body[j]].getMobilizedBodyIndex()};
        std::vector<MobilizerQIndex> which{MobilizerQIndex(0)};
        std::vector<double> coeff{1.0};
        for (decltype(C_rows)::InnerIterator it(C_rows, j); it; ++it) {
          if (it.value() == 0) continue;
          bodies.push_back(mobod[m.theta_body[independent[it.col()]]].getMobilizedBodyIndex());
          which.push_back(MobilizerQIndex(0));
          coeff.push_back(-it.value());
        }
        coeff.push_back(-m.theta0[j]);
        Vector a(static_cast<int>(coeff.size()));
        for (int i = 0; i < a.size(); ++i) a[i] = coeff[i];
        auto f = std::make_unique<Function::Linear>(a);
        Constraint::CoordinateCoupler(matter, f.release(), bodies, which);  // Simbody owns f
      }
    }
  }

  // The realized state and the index maps.
  void finish_state() {
    using namespace SimTK;
    const TwinModel& m = model;
    state = system.realizeTopology();
    system.realizeModel(state);
    theta_q.resize(m.n_theta());
    theta_u.resize(m.n_theta());
    for (int j = 0; j < m.n_theta(); ++j) {
      theta_q[j] = mobod[m.theta_body[j]].getFirstQIndex(state);
      theta_u[j] = mobod[m.theta_body[j]].getFirstUIndex(state);
    }
    const int nu = state.getNU();
    zero_mobility = Vector(nu, 0.0);
    zero_body =
        Vector_<SpatialVec>(matter.getNumBodies(), SpatialVec(SimTK::Vec3(0), SimTK::Vec3(0)));
  }

  VecX reduce(const SimTK::Vector& f_theta) const {  // Cᵀ f_θ
    VecX f(model.n_theta());
    for (int j = 0; j < model.n_theta(); ++j) f[j] = f_theta[theta_u[j]];
    return model.C.transpose() * f;
  }

  // Buffers of the timing entry points (time_*).
  SimTK::Vector bench_applied, bench_udot, bench_theta_ddot, bench_out;
  SimTK::Vector_<SimTK::SpatialVec> bench_A_GB;
  VecX bench_rest;                  // q̇ = 0
  SimTK::Matrix bench_h1, bench_D;  // h(e_b) by columns; D_sym(·, b, c) in column b n + c

  const VecX& rest() {  // q̇ = 0, sized by the first call
    if (bench_rest.size() != model.n()) bench_rest = VecX::Zero(model.n());
    return bench_rest;
  }

  // θ̇ = C (e_b + e_c) (c < 0: C e_b) written into the state; invalidates Velocity and above
  // only, so the realized Position stage stays.
  void set_unit_rates(int b, int c) {
    SimTK::Vector& su = state.updU();
    for (int j = 0; j < model.n_theta(); ++j) su[theta_u[j]] = 0;
    for (const int col : {b, c})
      if (col >= 0)
        for (SpMatX::InnerIterator it(model.C, col); it; ++it) su[theta_u[it.row()]] += it.value();
  }

  // Sets θ = C q + θ0, θ̇ = C q̇ (without temporaries: the timing entry points use it too) and
  // realizes `stage`. Closed loop: θ = g(q), θ̇ = G q̇, and each rod fitted between its ends
  // unless `fit_rods` is false (the timing entry points: a rod left as the last call set it
  // changes none of the work Simbody does, only its constraint errors).
  void set_state(const VecX& q, const VecX& qd, SimTK::Stage stage, bool fit_rods = true) {
    SimTK::Vector& sq = state.updQ();
    SimTK::Vector& su = state.updU();
    if (model.closed_loop()) {  // θ = g(q), θ̇ = G q̇, then the rods between their ends
      loops::joint_state(model, q, qd, loop_theta, loop_theta_dot);
      for (int j = 0; j < model.n_theta(); ++j) {
        sq[theta_q[j]] = loop_theta[j];
        su[theta_u[j]] = loop_theta_dot[j];
      }
      if (fit_rods) loops::fit_rods(system, state, model, mobod, rods);
      system.realize(state, stage);
      return;
    }
    for (int j = 0; j < model.n_theta(); ++j) {
      double theta = model.theta0[j], theta_dot = 0;
      for (decltype(C_rows)::InnerIterator it(C_rows, j); it; ++it) {
        theta += it.value() * q[it.col()];
        theta_dot += it.value() * qd[it.col()];
      }
      sq[theta_q[j]] = theta;
      su[theta_u[j]] = theta_dot;
    }
    system.realize(state, stage);
  }

  // θ, θ̇ and the energy of an integrator's state.
  TwinSample sample(const SimTK::State& st) const {
    system.realize(st, SimTK::Stage::Dynamics);
    const int nt = model.n_theta();
    TwinSample out;
    out.t = st.getTime();
    out.theta.resize(nt);
    out.theta_dot.resize(nt);
    for (int j = 0; j < nt; ++j) {
      out.theta[j] = st.getQ()[theta_q[j]];
      out.theta_dot[j] = st.getU()[theta_u[j]];
    }
    out.energy = system.calcEnergy(st);
    return out;
  }

  // Closed loop: q̈ of the coordinates by Simbody's constrained forward dynamics under these
  // applied forces.
  VecX constrained_qdd(const SimTK::Vector& applied,
                       const SimTK::Vector_<SimTK::SpatialVec>& body) {
    matter.calcAcceleration(state, applied, body, udot, A_GB);
    VecX out(model.n());
    for (int k = 0; k < model.n(); ++k) out[k] = udot[theta_u[model.coordinate_theta[k]]];
    return out;
  }

  // Closed loop: M^s as the inverse of q̈'s response to a unit force on each coordinate,
  // (M^s)⁻¹ e_k = q̈(e_k) − q̈(0), with a0 = q̈(no force).
  MatX constrained_mass(const VecX& a0) {
    const int n = model.n();
    MatX response(n, n);
    SimTK::Vector unit = zero_mobility;
    for (int k = 0; k < n; ++k) {
      const int u = theta_u[model.coordinate_theta[k]];
      unit[u] = 1;
      response.col(k) = constrained_qdd(unit, zero_body) - a0;
      unit[u] = 0;
    }
    return response.partialPivLu().inverse();
  }

  SimTK::Vector expand(const VecX& x) const {  // C x on Simbody's u layout
    SimTK::Vector out(state.getNU(), 0.0);
    const VecX y = model.C * x;
    for (int j = 0; j < model.n_theta(); ++j) out[theta_u[j]] = y[j];
    return out;
  }
};

SimbodyTwin::SimbodyTwin(TwinModel model) : impl_(std::make_unique<Impl>(std::move(model))) {}
SimbodyTwin::~SimbodyTwin() = default;

TwinEquations SimbodyTwin::equations(const VecX& q, const VecX& qd, const VecX& tau,
                                     const MatX* V) {
  try {
    return equations_unguarded(q, qd, tau, V);
  } catch (const std::exception& e) {  // SimTK's multi-line text, as one line
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
}

TwinEquations SimbodyTwin::equations_unguarded(const VecX& q, const VecX& qd, const VecX& tau,
                                               const MatX* V) {
  Impl& s = *impl_;
  const TwinModel& m = s.model;
  const int n = m.n(), nt = m.n_theta();
  TwinEquations out;
  s.set_state(q, qd, SimTK::Stage::Dynamics);
  if (m.closed_loop()) {
    out = closed_loop_equations(tau);
    if (V) out.MV = out.M * *V;
    return out;
  }

  bool plain = m.n() == nt;  // C = I, θ0 = 0: Simbody's own O(n) forward dynamics applies
  for (int k = 0; k < n && plain; ++k) plain = s.independent[k] == k;
  // Products alone where q̈ needs no M (a coupled tree solves M q̈ = Q − h with it).
  if (V && plain) {  // M V = Cᵀ M_θ C v, column by column, by Simbody's O(n) multiplyByM
    out.MV.resize(n, V->cols());
    SimTK::Vector MV;
    for (Eigen::Index c = 0; c < V->cols(); ++c) {
      s.matter.multiplyByM(s.state, s.expand(V->col(c)), MV);
      out.MV.col(c) = s.reduce(MV);
    }
  } else {  // M = Cᵀ M_θ C
    s.matter.calcM(s.state, s.M_theta);
    MatX Mt(nt, nt);
    for (int a = 0; a < nt; ++a)
      for (int b = 0; b < nt; ++b) Mt(a, b) = s.M_theta(s.theta_u[a], s.theta_u[b]);
    const MatX MtC = Mt * m.C;
    out.M = m.C.transpose() * MtC;
  }

  // h: residual with no applied force and θ̈ = 0 is the velocity (Coriolis, gyroscopic) term.
  s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                s.zero_mobility, s.residual);
  out.h = s.reduce(s.residual);

  // Q: what Simbody's force elements apply, as generalized forces, plus τ on q.
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  SimTK::Vector with_forces;
  s.matter.calcResidualForceIgnoringConstraints(s.state, mob, body, s.zero_mobility, with_forces);
  out.Q = s.reduce(s.residual - with_forces) + tau;

  if (plain) {
    SimTK::Vector applied = mob;
    for (int j = 0; j < nt; ++j) applied[s.theta_u[j]] += tau[j];
    s.matter.calcAccelerationIgnoringConstraints(s.state, applied, body, s.udot, s.A_GB);
    out.qdd.resize(n);
    for (int j = 0; j < nt; ++j) out.qdd[j] = s.udot[s.theta_u[j]];
  } else {
    out.qdd = out.M.llt().solve(out.Q - out.h);
    if (V) out.MV = out.M * *V, out.M = MatX();
  }
  return out;
}

// The closed loop's equations at the state set by equations_unguarded, from Simbody's
// constrained forward dynamics alone (twin.hpp).
TwinEquations SimbodyTwin::closed_loop_equations(const VecX& tau) {
  Impl& s = *impl_;
  const TwinModel& m = s.model;
  TwinEquations out;
  for (int i = 0; i < s.state.getNQErr(); ++i)
    out.loop_position_error = std::max(out.loop_position_error, std::abs(s.state.getQErr()[i]));
  for (int i = 0; i < s.state.getNUErr(); ++i)
    out.loop_velocity_error = std::max(out.loop_velocity_error, std::abs(s.state.getUErr()[i]));
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  const VecX a0 = s.constrained_qdd(s.zero_mobility, s.zero_body);  // −(M^s)⁻¹ h
  const VecX a_forces = s.constrained_qdd(mob, body);               // (M^s)⁻¹ (Q − τ − h)
  out.M = s.constrained_mass(a0);
  out.h = -out.M * a0;
  out.Q = out.M * (a_forces - a0) + tau;
  SimTK::Vector applied = mob;
  for (int k = 0; k < m.n(); ++k) applied[s.theta_u[m.coordinate_theta[k]]] += tau[k];
  out.qdd = s.constrained_qdd(applied, body);
  return out;
}

VecX SimbodyTwin::inverse_dynamics(const VecX& q, const VecX& qd, const VecX& qdd) {
  try {
    return inverse_dynamics_unguarded(q, qd, qdd);
  } catch (const std::exception& e) {
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
}

VecX SimbodyTwin::inverse_dynamics_unguarded(const VecX& q, const VecX& qd, const VecX& qdd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics);
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  if (s.model.closed_loop()) {  // τ = M^s (q̈ − q̈(Simbody's forces))
    const VecX a_forces = s.constrained_qdd(mob, body);
    const MatX M = s.constrained_mass(s.constrained_qdd(s.zero_mobility, s.zero_body));
    return M * (qdd - a_forces);
  }
  // residual = M_θ θ̈ + h_θ − Q_θ with θ̈ = C q̈;  τ = Cᵀ residual
  s.matter.calcResidualForceIgnoringConstraints(s.state, mob, body, s.expand(qdd), s.residual);
  return s.reduce(s.residual);
}

void SimbodyTwin::time_mass_and_bias(const VecX& q, const VecX& qd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  s.matter.calcM(s.state, s.M_theta);
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_bias(const VecX& q, const VecX& qd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Velocity, kTiming);
  s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_forward(const VecX& q, const VecX& qd, const VecX& tau) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  const SimTK::Vector& mob = s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics);
  s.bench_applied = mob;  // allocates on the first call only
  for (int k = 0; k < s.model.n(); ++k)
    if (s.independent[k] >= 0) s.bench_applied[s.theta_u[s.independent[k]]] += tau[k];
  const SimTK::Vector_<SimTK::SpatialVec>& body =
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics);
  if (s.matter.getNumConstraints() == 0)
    s.matter.calcAccelerationIgnoringConstraints(s.state, s.bench_applied, body, s.bench_udot,
                                                 s.bench_A_GB);
  else  // the coupling as coordinate couplers: the constrained (coupled) motion
    s.matter.calcAcceleration(s.state, s.bench_applied, body, s.bench_udot, s.bench_A_GB);
}

void SimbodyTwin::time_inverse(const VecX& q, const VecX& qd, const VecX& qdd) {
  Impl& s = *impl_;
  s.set_state(q, qd, SimTK::Stage::Dynamics, kTiming);
  const int nu = s.state.getNU();
  if (s.bench_theta_ddot.size() != nu) s.bench_theta_ddot = SimTK::Vector(nu, 0.0);
  for (int j = 0; j < s.model.n_theta(); ++j) {
    double theta_ddot = 0;
    for (decltype(s.C_rows)::InnerIterator it(s.C_rows, j); it; ++it)
      theta_ddot += it.value() * qdd[it.col()];
    s.bench_theta_ddot[s.theta_u[j]] = theta_ddot;
  }
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.bench_theta_ddot,
      s.bench_out);
}

void SimbodyTwin::time_mass(const VecX& q) {
  Impl& s = *impl_;
  s.set_state(q, s.rest(), SimTK::Stage::Position, kTiming);
  s.matter.calcM(s.state, s.M_theta);
}

void SimbodyTwin::time_gravity(const VecX& q) {
  Impl& s = *impl_;
  s.set_state(q, s.rest(), SimTK::Stage::Dynamics, kTiming);
  s.matter.calcResidualForceIgnoringConstraints(
      s.state, s.system.getMobilityForces(s.state, SimTK::Stage::Dynamics),
      s.system.getRigidBodyForces(s.state, SimTK::Stage::Dynamics), s.zero_mobility, s.bench_out);
}

void SimbodyTwin::time_tensor(const VecX& q) {
  Impl& s = *impl_;
  const int n = s.model.n(), nu = s.state.getNU();
  s.set_state(q, s.rest(), SimTK::Stage::Position, kTiming);
  if (s.bench_h1.nrow() != nu || s.bench_h1.ncol() != n) {  // first call only
    s.bench_h1.resize(nu, n);
    s.bench_D.resize(nu, n * n);
  }
  // h(e_b), b = 1…n: velocity-stage residuals with no force and θ̈ = 0.
  for (int b = 0; b < n; ++b) {
    s.set_unit_rates(b, -1);
    s.system.realize(s.state, SimTK::Stage::Velocity);
    s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                  s.zero_mobility, s.bench_out);
    for (int i = 0; i < nu; ++i) s.bench_h1(i, b) = s.bench_out[i];
  }
  // D_sym(·, b, c) = (h(e_b + e_c) − h(e_b) − h(e_c)) / 2, b ≤ c, mirrored.
  for (int b = 0; b < n; ++b)
    for (int c = b; c < n; ++c) {
      s.set_unit_rates(b, c);
      s.system.realize(s.state, SimTK::Stage::Velocity);
      s.matter.calcResidualForceIgnoringConstraints(s.state, s.zero_mobility, s.zero_body,
                                                    s.zero_mobility, s.bench_out);
      for (int i = 0; i < nu; ++i) {
        const double d = 0.5 * (s.bench_out[i] - s.bench_h1(i, b) - s.bench_h1(i, c));
        s.bench_D(i, b * n + c) = d;
        s.bench_D(i, c * n + b) = d;
      }
    }
}

bool SimbodyTwin::can_simulate(std::string* why_not) const {
  if (!impl_->couplers && why_not)
    *why_not =
        "a coordinate drives no joint directly, so the coupling is not a set of "
        "coordinate couplers";
  return impl_->couplers;
}

const char* simbody_integrator_name(SimbodyIntegrator which) {
  switch (which) {
    case SimbodyIntegrator::RungeKuttaMerson:
      return "RungeKuttaMerson";
    case SimbodyIntegrator::RungeKutta3:
      return "RungeKutta3";
    case SimbodyIntegrator::RungeKuttaFeldberg:
      return "RungeKuttaFeldberg";
    case SimbodyIntegrator::Verlet:
      return "Verlet";
    case SimbodyIntegrator::SemiExplicitEuler2:
      return "SemiExplicitEuler2";
    case SimbodyIntegrator::CPodes:
      return "CPodes";
  }
  return "unknown";
}

// Simbody 3.7 (Debian's libsimbody-dev) ships all six (simmath/*Integrator.h); CPodes only
// where its bundled SUNDIALS is not shadowed (cpodes_conflict).
std::vector<SimbodyIntegrator> simbody_integrators() {
  std::vector<SimbodyIntegrator> out{
      SimbodyIntegrator::RungeKuttaMerson, SimbodyIntegrator::RungeKutta3,
      SimbodyIntegrator::RungeKuttaFeldberg, SimbodyIntegrator::Verlet,
      SimbodyIntegrator::SemiExplicitEuler2};
  if (cpodes_conflict().empty()) out.push_back(SimbodyIntegrator::CPodes);
  return out;
}

// As before the integrator choice: empty without couplers, and a failed integration throws
// (callers such as validate() index every sample).
std::vector<TwinSample> SimbodyTwin::simulate(const VecX& q0, const VecX& qd0,
                                              const std::vector<double>& times, double accuracy) {
  TwinRun run = simulate(q0, qd0, times, accuracy, SimbodyIntegrator::RungeKuttaMerson);
  if (!run.stats.ok && can_simulate()) throw femdyn::Error(run.stats.failure);
  return std::move(run.samples);
}

namespace {

// Adds the wall time of its scope to `total`, also when the scope is left by an exception.
struct Stopwatch {
  using Clock = std::chrono::steady_clock;
  double& total;
  Clock::time_point start = Clock::now();
  ~Stopwatch() { total += std::chrono::duration<double>(Clock::now() - start).count(); }
};

// Why `which` must not be run at `accuracy` to `times`, or "": Simbody would abort in an
// assert (not throw) on these.
std::string why_not_run(SimbodyIntegrator which, double accuracy,
                        const std::vector<double>& times) {
  if (!(accuracy > 0 && accuracy < 1))
    return "accuracy must be in (0, 1), not " + std::to_string(accuracy);
  for (std::size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]) || !(times[i] >= (i ? times[i - 1] : 0.0)))
      return "sample times must be finite, >= 0 and non-decreasing";
  if (which == SimbodyIntegrator::CPodes) return cpodes_conflict();
  return {};
}

// One line for an integrator that returned from stepTo(t) short of t.
std::string stopped_early(SimbodyIntegrator which, const SimTK::Integrator& integ, double t) {
  const std::string reason =
      integ.isSimulationOver()
          ? SimTK::Integrator::getTerminationReasonString(integ.getTerminationReason())
          : std::string("no termination reason");
  return std::string(simbody_integrator_name(which)) +
         " stopped at t = " + std::to_string(integ.getTime()) + " short of " + std::to_string(t) +
         ": " + one_line(reason);
}

void count(const SimTK::Integrator& integ, TwinRunStats& stats) {
  stats.steps = integ.getNumStepsTaken();
  stats.attempts = integ.getNumStepsAttempted();
  stats.realizations = integ.getNumRealizations();
  stats.error_test_failures = integ.getNumErrorTestFailures();
  stats.convergence_failures = integ.getNumConvergenceTestFailures();
}

}  // namespace

// Settings: setAccuracy and setConstraintTolerance at `accuracy`; Simbody's defaults otherwise,
// set explicitly: setReturnEveryInternalStep(false) and setAllowInterpolation(true). StepToEach
// drives a TimeStepper, whose stepTo(t) makes t a scheduled event time too, so a step ends at
// every sample; Interpolate calls the integrator's own stepTo(t) (no scheduled event), with the
// final time at the last sample, and samples its interpolated states (twin.hpp). Only
// initialize() and stepTo() are timed.
TwinRun SimbodyTwin::simulate(const VecX& q0, const VecX& qd0, const std::vector<double>& times,
                              double accuracy, SimbodyIntegrator which, TwinSampling sampling,
                              const TwinRunLimits& limits) {
  Impl& s = *impl_;
  TwinRun run;
  TwinRunStats& stats = run.stats;
  // Not run: no coordinate couplers, or what Simbody would abort on.
  if (can_simulate(&stats.failure)) stats.failure = why_not_run(which, accuracy, times);
  if (!stats.failure.empty()) {
    stats.ok = false;
    return run;
  }
  std::unique_ptr<SimTK::Integrator> integ;
  try {
    s.set_state(q0, qd0, SimTK::Stage::Velocity);
    s.state.setTime(0);
    integ = make_integrator(which, s.system);
    integ->setAccuracy(accuracy);
    integ->setConstraintTolerance(accuracy);
    integ->setReturnEveryInternalStep(false);
    integ->setAllowInterpolation(true);
    const bool interpolate = sampling == TwinSampling::Interpolate;
    if (interpolate && !times.empty() && times.back() > 0) integ->setFinalTime(times.back());
    // A time bound: the integrator hands control back every kChunk steps (ReachedStepLimit),
    // and the stepper every significant state, so the clock can be read between steps.
    constexpr int kChunk = 16;
    const bool bounded = limits.wall_time > 0;
    if (bounded) integ->setInternalStepLimit(kChunk);
    SimTK::TimeStepper stepper(s.system, *integ);
    if (bounded) stepper.setReportAllSignificantStates(true);
    const auto start = std::chrono::steady_clock::now();
    const auto out_of_time = [&] {
      return bounded &&
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >
                 limits.wall_time;
    };
    {
      Stopwatch timed{stats.wall_time};
      if (interpolate)
        integ->initialize(s.state);
      else
        stepper.initialize(s.state);
    }
    bool timed_out = false;
    for (double t : times) {
      if (t > 0) {
        Stopwatch timed{stats.wall_time};
        if (interpolate) {
          // Returns at t, or earlier at the start of the continuous interval or a step limit.
          while (integ->getTime() < t && !integ->isSimulationOver() && !(timed_out = out_of_time()))
            if (integ->stepTo(t) == SimTK::Integrator::EndOfSimulation) break;
        } else if (bounded) {  // returns at every significant state, and every kChunk steps
          while (integ->getTime() < t && !integ->isSimulationOver() && !(timed_out = out_of_time()))
            stepper.stepTo(t);
        } else {
          stepper.stepTo(t);
        }
      }
      if (timed_out) {
        stats.ok = false;
        stats.out_of_time = true;
        char text[160];
        std::snprintf(text, sizeof text,
                      " stopped at t = %.3g s of %.3g s: its time bound of %.3g s ran out",
                      integ->getTime(), times.back(), limits.wall_time);
        stats.failure = simbody_integrator_name(which) + std::string(text);
        break;
      }
      if (std::abs(integ->getTime() - t) > 1e-12 * std::max(1.0, t)) {
        stats.ok = false;
        stats.failure = stopped_early(which, *integ, t);
        break;
      }
      run.samples.push_back(s.sample(integ->getState()));
      if (limits.on_sample) limits.on_sample(t);
    }
  } catch (const std::exception& e) {
    stats.ok = false;
    stats.failure = std::string(simbody_integrator_name(which)) + " failed: " + one_line(e.what());
  }
  if (integ) count(*integ, stats);
  return run;
}

}  // namespace femdyn::validation
