// MujocoPeer: a URDF robot loaded by MuJoCo's own importer (mj_loadXML), a second independent
// peer beside Simbody (validation/urdf_twin.hpp), evaluated at femdyn's q, v and returned in
// femdyn's coordinates. This header uses only Eigen; mujoco_peer.cpp is the one file that
// includes MuJoCo (built when CMake finds it: FEMDYN_WITH_MUJOCO).
//
// Loading (docs/validation.md, "MuJoCo"): a copy of the URDF, with <visual> and <collision>
// removed, each <inertial> rewritten in exact principal axes (MuJoCo's compiler finds them only
// roughly), and a <mujoco><compiler …/></mujoco> that keeps the inertias as given
// (inertiafromgeom="false", balanceinertia="false", no bound on mass or inertia, no fusing of
// static bodies). The root link becomes MuJoCo's world body (renamed "world"); with `floating`,
// a link "world" and a "floating" URDF joint are added above it instead, which MuJoCo turns
// into a free joint of the root. After compiling: gravity as given, the constraint solver and
// contacts off (joint limits and frictionloss are constraints in MuJoCo, none in femdyn),
// armature 0 unless given (then as femdyn's); joint damping stays a passive force in both.
//
// Quantities: M = mj_fullM after mj_crb; τ = mj_inverse (qfrc_inverse); q̈ = mj_forward with the
// constraint solver disabled, so qacc is its smooth part, qacc_smooth.
//
// Coordinates. MuJoCo's dofs are matched to femdyn's coordinates by joint name (hinge and slide
// joints only). The free joint: qpos = (p, quaternion w, x, y, z) as femdyn's q; MuJoCo's qvel =
// (ṗ in world axes, ω in the body's axes), femdyn's v = (ṗ, ω) both in the body's axes. So
// qvel = P v with P orthogonal (R(q) on the linear triple, a permutation elsewhere), and
// qacc = P v̇ + Ṗ v, Ṗ v = (R (ω × ṗ_B), 0): M_v = Pᵀ M P, τ_v = Pᵀ τ, q̈_v = Pᵀ (qacc − Ṗ v),
// and an applied force enters as P τ_v (P⁻ᵀ = P).
#pragma once
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

namespace femdyn::validation {

class MujocoPeer {
 public:
  // `coordinates`: femdyn's coordinate names in its order (Model::coordinate_names); with
  // `floating` the first six are the root's free joint and the rest name URDF joints. Throws
  // std::runtime_error, one line naming the file: a URDF MuJoCo cannot load (its message), or a
  // joint that does not map one to one (a <mimic> joint, a floating or planar joint inside).
  // `armature` (n, or empty: 0): each coordinate's reflected rotor inertia I_a G², set as
  // MuJoCo's dof_armature (URDF has no armature: femdyn's JSON or Builder gives it).
  MujocoPeer(const std::string& urdf_path, const Eigen::Vector3d& gravity, bool floating,
             const std::vector<std::string>& coordinates,
             const Eigen::VectorXd& armature = Eigen::VectorXd());
  // An MJCF file compiled by MuJoCo itself (docs/validation.md, "MJCF"): `joints` are femdyn's
  // moving joints in its coordinate order, each by name with its rates (1; 3 for a ball; 6 for a
  // free joint, whose q is MuJoCo's qpos and whose v is in the body's axes, as above). An
  // unnamed MuJoCo joint is "joint<i>", i its index (for a coupled model, the joints' θ order).
  // Meshes whose files exist are kept (paths made absolute, exactmeshinertia: see
  // keep_meshes); other mesh geoms, assets and contact pairs are removed, so that a model loads
  // without its visual meshes, and actuators, sensors, tendons, keyframes and the integrator,
  // which the quantities compared do not depend on (and MuJoCo 2.2 may not read); constraints
  // (equalities included), contacts and fluid forces are off, and damping and springs on ball
  // and free joints are zeroed: what the reader reports as not modelled.
  struct MjcfJoint {
    std::string name;
    int rates;
  };
  MujocoPeer(const std::string& mjcf_path, const Eigen::Vector3d& gravity,
             const std::vector<MjcfJoint>& joints);
  ~MujocoPeer();
  MujocoPeer(const MujocoPeer&) = delete;
  MujocoPeer& operator=(const MujocoPeer&) = delete;

  // At a state in femdyn's coordinates (q of n_q entries, v, v̇ and τ of n).
  Eigen::MatrixXd mass(const Eigen::VectorXd& q);
  Eigen::VectorXd inverse(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd& qdd);
  Eigen::VectorXd forward(const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd& tau);

  // Timing (femdyn_bench, femdyn bench): a state converted once into MuJoCo's coordinates
  // (qpos, qvel, qacc = P v̇ + Ṗ v, qfrc_applied = P τ); the time_* calls then do MuJoCo's own
  // work only: copy that state into mjData and call
  //   time_mass:    mj_kinematics, mj_comPos, mj_crb, mj_fullM   (M)
  //   time_inverse: mj_inverse                                   (τ)
  //   time_forward: mj_forward, constraints off                  (q̈, qacc_smooth)
  struct State {
    Eigen::VectorXd qpos, qvel, qacc, qfrc;
  };
  State state(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& tau,
              const Eigen::VectorXd& qdd) const;
  void time_mass(const State& s);
  void time_inverse(const State& s);
  void time_forward(const State& s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace femdyn::validation
