// An independent Simbody model of a URDF file, built from the XML directly — not from femdyn's
// import (io/urdf_loader) — so that comparing it with femdyn's equations of the same file checks
// the import itself: the rpy convention (Simbody's own space-fixed X-Y-Z sequence), the rotation
// of the inertia out of the <inertial> frame (Inertia::reexpress) and its shift to the link
// origin, the tree, fixed, planar, spherical and floating joints, axes, mimic couplings and
// damping. Gravity is given (URDF has none; femdyn's default for URDF is (0, 0, −9.81)). Like
// twin.hpp, this header uses only Eigen; urdf_twin.cpp is C++17 without NDEBUG.
#pragma once
#include <Eigen/Dense>
#include <memory>
#include <string>
#include <vector>

namespace femdyn::validation {

struct UrdfTwinEquations {
  Eigen::MatrixXd M;
  Eigen::VectorXd h, Q;  // Q: gravity and joint damping (no actuation)
};

class UrdfTwin {
 public:
  // With `floating`, the root link moves on a Free mobilizer (femdyn's --floating-base);
  // otherwise it is welded to the ground. Throws on bad XML.
  // The links welded by fixed joints are one body with their merged mass (a sensor link need not
  // be physical alone); with `balance_inertia` a body's non-physical inertia is replaced by the
  // nearest physical one, as femdyn's --balance-inertia does.
  UrdfTwin(const std::string& urdf_path, const Eigen::Vector3d& gravity, bool floating = false,
           bool balance_inertia = false);
  ~UrdfTwin();
  UrdfTwin(const UrdfTwin&) = delete;
  UrdfTwin& operator=(const UrdfTwin&) = delete;

  // The equations in femdyn's coordinates, found by their names: `rate_names` name v (a joint's
  // own name for one rate; "NAME.x", "NAME.y", "NAME.theta" for a planar joint; "NAME.vx" …
  // "NAME.wz" for a floating one, the floating root named after its link) and
  // `configuration_names` name q likewise ("NAME.x" … "NAME.qz" for a floating joint: its
  // child's origin in the joint frame and the quaternion (w, x, y, z); v and ω in the child's
  // axes, docs/notation.md). Simbody's equations over all joints, reduced by the mimic
  // relations θ_j = k θ_leader + offset.
  UrdfTwinEquations equations(const std::vector<std::string>& rate_names,
                              const std::vector<std::string>& configuration_names,
                              const Eigen::VectorXd& q, const Eigen::VectorXd& qd);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace femdyn::validation
