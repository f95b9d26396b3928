// The twin's kinematics for control (twin.hpp, SimbodyTwin::kinematics): frames fixed on bodies,
// the centre of mass and the central momentum, read off Simbody's own operators. Compiled like
// twin.cpp (C++17, without NDEBUG).
//
// Simbody's spatial vectors are (angular, linear); femdyn's frame and momentum vectors are
// (linear, angular): every one is reordered here. The velocities are physical (a frame's
// origin velocity and angular velocity in ground), so the rate map u = P v of ball and free
// joints does not enter them; only the Jacobian's columns, u = P θ̇(e_k), see it.
#include <Simbody.h>

#include <vector>

#include "core/model/errors.hpp"
#include "validation/simtk_convert.hpp"
#include "validation/twin_impl.hpp"
#include "validation/twin_loops.hpp"

namespace femdyn::validation {

namespace {

using Vec6 = ::Eigen::Matrix<double, 6, 1>;

// Simbody's (angular, linear) as femdyn's (linear, angular).
Vec6 linear_first(const SimTK::SpatialVec& V) {
  Vec6 out;
  out << from_simtk(V[1]), from_simtk(V[0]);
  return out;
}

// τ leaves the discrete forces however the scope is left: the equations and trajectories that
// use the same state must see Simbody's force elements alone.
class AppliedWhileInScope {
 public:
  AppliedWhileInScope(const SimTK::Force::DiscreteForces& forces, SimTK::State& state,
                      const SimTK::Vector& f)
      : forces_(forces), state_(state) {
    forces_.setAllMobilityForces(state_, f);
  }
  ~AppliedWhileInScope() { forces_.clearAllMobilityForces(state_); }
  AppliedWhileInScope(const AppliedWhileInScope&) = delete;
  AppliedWhileInScope& operator=(const AppliedWhileInScope&) = delete;

 private:
  const SimTK::Force::DiscreteForces& forces_;
  SimTK::State& state_;
};

}  // namespace

SimTK::Vector SimbodyTwin::Impl::independent_forces(const VecX& tau) const {
  VecX f_theta = VecX::Zero(model.n_theta());
  for (int k = 0; k < model.n(); ++k) f_theta[independent[k]] = tau[k];
  return scatter(f_theta, rot);
}

TwinKinematics SimbodyTwin::kinematics(const VecX& q, const VecX& qd, const VecX& tau,
                                       const std::vector<TwinFrame>& frames, bool jacobian) {
  try {
    // Where the coupling cannot be posed as couplers Simbody's own q̈ is the reduced
    // equations' (M q̈ = Q − h, as equations() solves them).
    const VecX qdd = impl_->couplers ? VecX() : equations_unguarded(q, qd, tau, nullptr).qdd;
    return impl_->kinematics(q, qd, tau, qdd, frames, jacobian);
  } catch (const std::exception& e) {  // SimTK's multi-line text, as one line
    throw femdyn::Error("Simbody failed at this state: " + one_line(e.what()));
  }
}

// J's column k: the frames' velocities at q̇ = e_k, u = P θ̇(e_k) with θ̇ = C e_k (a tree)
// or G e_k (a closed loop: the laws' chain rule; the rods' u stay 0, they carry no frame).
MatX SimbodyTwin::Impl::frame_jacobians(const VecX& q, const std::vector<TwinFrame>& frames,
                                        const std::vector<SimTK::Transform>& X_BF) const {
  using namespace SimTK;
  const int nf = static_cast<int>(frames.size());
  const auto body = [&](int f) -> const MobilizedBody& { return mobod[frames[f].body]; };
  const int n = model.n();
  Array_<MobilizedBodyIndex> bodies;
  Array_<SimTK::Vec3> stations;
  for (int f = 0; f < nf; ++f) {
    bodies.push_back(body(f).getMobilizedBodyIndex());
    stations.push_back(X_BF[f].p());
  }
  MatX J(6 * nf, n);
  VecX e = VecX::Zero(n), theta, theta_dot;
  Vector_<SpatialVec> JFu;
  for (int k = 0; k < n; ++k) {
    e.setZero();
    e[k] = 1;
    Vector u;
    if (model.closed_loop()) {
      loops::joint_state(model, q, e, theta, theta_dot);
      u = scatter(theta_dot, rot);
    } else {
      u = expand(e);
    }
    matter.multiplyByFrameJacobian(state, bodies, stations, u, JFu);
    for (int f = 0; f < nf; ++f) J.block<6, 1>(6 * f, k) = linear_first(JFu[f]);
  }
  return J;
}

// Accelerations under Simbody's forward dynamics with τ on the coordinates.
void SimbodyTwin::Impl::accelerations(const VecX& tau, const VecX& qdd,
                                      const std::vector<TwinFrame>& frames,
                                      const std::vector<SimTK::Transform>& X_BF,
                                      TwinKinematics& out) {
  using namespace SimTK;
  const int nf = static_cast<int>(frames.size());
  const auto body = [&](int f) -> const MobilizedBody& { return mobod[frames[f].body]; };
  out.acceleration.resize(6, nf);
  if (couplers) {  // a tree, linear couplers or a closed loop: realized with τ applied
    const AppliedWhileInScope applied(tau_forces, state, independent_forces(tau));
    system.realize(state, Stage::Acceleration);
    for (int f = 0; f < nf; ++f)
      out.acceleration.col(f) = linear_first(body(f).findFrameAccelerationInGround(state, X_BF[f]));
    out.com_acceleration = from_simtk(matter.calcSystemMassCenterAccelerationInGround(state));
    return;
  }
  // u̇ = P C q̈ + Ṗ v from the reduced equations' q̈; the bodies' A_GB by Simbody's kinematics,
  // each shifted to a frame's origin (a_F = a_B + α × r + ω × (ω × r)) or its mass centre.
  Vector_<SpatialVec> A_GB;
  matter.calcBodyAccelerationFromUDot(state, expand(qdd) + pdot_v, A_GB);
  const auto shifted = [&](const MobilizedBody& B, const SimTK::Vec3& station) {
    return shiftAccelerationBy(A_GB[B.getMobilizedBodyIndex()], B.getBodyAngularVelocity(state),
                               B.getBodyRotation(state) * station);
  };
  for (int f = 0; f < nf; ++f)
    out.acceleration.col(f) = linear_first(shifted(body(f), X_BF[f].p()));
  SimTK::Vec3 ma(0);  // Σ m_b a_cb
  for (MobilizedBodyIndex b(1); b < matter.getNumBodies(); ++b) {
    const MobilizedBody& B = matter.getMobilizedBody(b);
    const MassProperties& props = B.getBodyMassProperties(state);
    ma += props.getMass() * shifted(B, props.getMassCenter())[1];
  }
  out.com_acceleration = from_simtk(ma) / out.mass;
}

TwinKinematics SimbodyTwin::Impl::kinematics(const VecX& q, const VecX& qd, const VecX& tau,
                                             const VecX& qdd, const std::vector<TwinFrame>& frames,
                                             bool jacobian) {
  using namespace SimTK;
  const int nf = static_cast<int>(frames.size());
  TwinKinematics out;
  set_state(q, qd, Stage::Velocity);
  std::vector<Transform> X_BF;
  for (const TwinFrame& f : frames) X_BF.emplace_back(to_simtk(f.R_BF), to_simtk(f.p_BF));
  const auto body = [&](int f) -> const MobilizedBody& { return mobod[frames[f].body]; };

  // Poses X_GF = X_GB X_BF and velocities (ω_B, v_B + ω_B × R_GB p_BF).
  out.velocity.resize(6, nf);
  for (int f = 0; f < nf; ++f) {
    const Transform X_GF = body(f).findFrameTransformInGround(state, X_BF[f]);
    out.R.push_back(from_simtk(X_GF.R().asMat33()));
    out.p.push_back(from_simtk(X_GF.p()));
    out.velocity.col(f) = linear_first(body(f).findFrameVelocityInGround(state, X_BF[f]));
  }

  // The mechanism: every mobilized body but Ground (a closed loop's rods included).
  out.mass = matter.calcSystemMass(state);
  out.com = from_simtk(matter.calcSystemMassCenterLocationInGround(state));
  out.inertia_com = from_simtk(matter.calcSystemCentralInertiaInGround(state).toMat33());
  out.com_velocity = from_simtk(matter.calcSystemMassCenterVelocityInGround(state));
  out.momentum = linear_first(matter.calcSystemCentralMomentum(state));

  if (jacobian) out.J = frame_jacobians(q, frames, X_BF);

  accelerations(tau, qdd, frames, X_BF, out);
  return out;
}

}  // namespace femdyn::validation
