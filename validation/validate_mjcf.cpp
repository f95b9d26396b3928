// validate_mjcf_import (validation/validate.hpp): an MJCF model against MuJoCo's own compile.
#include <algorithm>
#include <random>

#include "core/equations.hpp"
#include "core/joints/passive.hpp"
#include "core/sampling.hpp"
#include "validation/mujoco_peer.hpp"
#include "validation/validate.hpp"

namespace femdyn::validation {

std::optional<QuantityError> validate_mjcf_import(const Model& m, const std::string& path,
                                                  int mesh_masses, const ValidationOptions& o,
                                                  std::string& why) {
  std::vector<const Joint*> moving;  // in rate order, as the peer maps them
  for (const Body& b : m.bodies)
    if (b.joint.idx_v >= 0) moving.push_back(&b.joint);
  std::sort(moving.begin(), moving.end(),
            [](const Joint* a, const Joint* b) { return a->idx_v < b->idx_v; });
  std::vector<MujocoPeer::MjcfJoint> joints;
  int rates = 0;
  for (const Joint* j : moving) {
    joints.push_back({j->name, j->nv});
    rates += j->nv;
  }
  if (rates != m.n()) {
    why = "femdyn holds an <equality joint> as a coupling: " + std::to_string(m.n()) +
          " coordinates against MuJoCo's " + std::to_string(rates) + " dofs";
    return std::nullopt;
  }
  std::unique_ptr<MujocoPeer> peer;
  try {
    peer = std::make_unique<MujocoPeer>(path, m.gravity, joints);
  } catch (const std::exception& e) {
    why = e.what();
    return std::nullopt;
  }
  double tolerance = o.tolerance > 0 ? o.tolerance : pointwise_tolerance(m);
  if (mesh_masses > 0) {  // MuJoCo rounds mesh vertices to float and re-centres them in float
    tolerance = std::max(tolerance, 1e-6);
    why = "the mass of " + std::to_string(mesh_masses) + " mesh geom" +
          (mesh_masses > 1 ? "s" : "") +
          " compared to 1e-6: MuJoCo holds mesh vertices in single precision";
  }
  QuantityError e{"mujoco", 0, 0, tolerance};
  Workspace ws(m);
  std::mt19937 rng(o.seed);
  for (int k = 0; k < o.states; ++k) {
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), o.qd_scale, rng);
    const VecX qdd = random_uniform(m.n(), 1, rng), tau = random_uniform(m.n(), 1, rng);
    const VecX friction = coulomb_forces(m, qd);
    mass_matrix(m, ws, q);
    accumulate(e, ws.Ms, peer->mass(q));
    inverse_dynamics(m, ws, q, qd, qdd);
    accumulate(e, ws.tau, peer->inverse(q, qd, qdd) - friction, bias_floor(ws.Ms, qd));
    if (forward_dynamics(m, ws, q, qd, tau).ok)
      accumulate(e, ws.qdd, peer->forward(q, qd, tau + friction));
  }
  return e;
}

}  // namespace femdyn::validation
