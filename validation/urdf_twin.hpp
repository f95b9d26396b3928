// An independent Simbody model of a URDF file, built from the XML directly — not from femdyn's
// import (io/urdf_loader) — so that comparing it with femdyn's equations of the same file checks
// the import itself: the rpy convention (Simbody's own space-fixed X-Y-Z sequence), the rotation
// of the inertia out of the <inertial> frame (Inertia::reexpress) and its shift to the link
// origin, the tree, fixed joints, axes, mimic couplings and damping. Gravity is given (URDF has
// none; femdyn's default for URDF is (0, 0, −9.81)).
// Like twin.hpp, this header uses only Eigen; urdf_twin.cpp is C++17 without NDEBUG.
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
  UrdfTwin(const std::string& urdf_path, const Eigen::Vector3d& gravity, bool floating = false);
  ~UrdfTwin();
  UrdfTwin(const UrdfTwin&) = delete;
  UrdfTwin& operator=(const UrdfTwin&) = delete;

  // The equations in the coordinates `names` (movable, non-mimic joints by name, in any order):
  // Simbody's over all joints, reduced by the mimic relations θ_j = k θ_leader + offset.
  // With a floating root, q and q̇ start with the root's own 7 and 6 (q: x, y, z, qw, qx, qy, qz
  // of the root link in the world; v: its origin's velocity and its ω, both in the root's axes,
  // docs/notation.md), and the equations' first 6 rows and columns are those rates; `names`
  // names the rest.
  UrdfTwinEquations equations(const std::vector<std::string>& names, const Eigen::VectorXd& q,
                              const Eigen::VectorXd& qd);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace femdyn::validation
