// MJCF import (io/mjcf_loader.hpp) against MuJoCo's own compile of the same file
// (validation/mujoco_peer.hpp): M^s, inverse and forward dynamics at random states, femdyn's own
// feature files and public models. Built only when CMake finds MuJoCo (FEMDYN_WITH_MUJOCO).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include "core/equations.hpp"
#include "core/sampling.hpp"
#include "io/model_loader.hpp"
#include "tests/helpers.hpp"
#include "validation/mujoco_peer.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string mjcf_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/tests/data/mjcf/" + name;
}

// femdyn's moving joints in coordinate order, as the peer maps them.
std::vector<validation::MujocoPeer::MjcfJoint> peer_joints(const Model& m) {
  std::vector<validation::MujocoPeer::MjcfJoint> out;
  std::vector<const Joint*> moving;
  for (const Body& b : m.bodies)
    if (b.joint.idx_v >= 0) moving.push_back(&b.joint);
  std::sort(moving.begin(), moving.end(),
            [](const Joint* a, const Joint* b) { return a->idx_v < b->idx_v; });
  for (const Joint* j : moving) out.push_back({j->name, j->nv});
  return out;
}

struct Errors {
  double mass = 0, inverse = 0, forward = 0;
};

// The largest relative errors over random states.
Errors against_mujoco(const std::string& path) {
  const Model m = load_model(path);
  validation::MujocoPeer peer(path, m.gravity, peer_joints(m));
  Workspace ws(m);
  std::mt19937 rng(11);
  Errors e;
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_posture(m, rng), qd = random_uniform(m.n(), 2, rng);
    const VecX qdd = random_uniform(m.n(), 5, rng), tau = random_uniform(m.n(), 1, rng);
    mass_matrix(m, ws, q);
    e.mass = std::max(e.mass, rel_error(ws.Ms, peer.mass(q)));
    inverse_dynamics(m, ws, q, qd, qdd);
    e.inverse = std::max(e.inverse, rel_error(ws.tau, peer.inverse(q, qd, qdd)));
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    e.forward = std::max(e.forward, rel_error(ws.qdd, peer.forward(q, qd, tau)));
  }
  return e;
}

}  // namespace

TEST_CASE("MJCF: every feature the reader reads equals MuJoCo's compile of the same file",
          "[mjcf][mujoco][validation]") {
  for (const char* file : {"features.xml", "floating.xml"}) {
    INFO(file);
    const Errors e = against_mujoco(mjcf_path(file));
    CHECK(e.mass < 1e-10);
    CHECK(e.inverse < 1e-10);
    CHECK(e.forward < 1e-10);
  }
}

// MuJoCo's compiler finds a full tensor's principal axes by an iteration that stops early (M^s
// off by 1.5e-10 on features.xml's forearm given as fullinertia), so fullinertia is checked by a
// relation instead: R diag(d) Rᵀ written as fullinertia is the same body as diag(d) turned by R.
TEST_CASE("MJCF: fullinertia is the same body as diaginertia turned by quat", "[mjcf]") {
  Scratch scratch("mjcf_fullinertia");
  const Eigen::Quaterniond turn = Eigen::Quaterniond(0.7, 0.1, 0.2, 0.3).normalized();
  const Mat3 I = turn.toRotationMatrix() * Vec3(0.011, 0.012, 0.004).asDiagonal() *
                 turn.toRotationMatrix().transpose();
  const auto write = [&](const std::string& name, const std::string& inertial) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path) << "<mujoco><worldbody><body name=\"a\" pos=\"0 0 1\">"
                           "<joint name=\"j1\" axis=\"1 0 0\"/><joint name=\"j2\" axis=\"0 1 1\"/>"
                           "<inertial pos=\"0.1 0.2 0.3\" mass=\"0.7\" "
                        << inertial << "/></body></worldbody></mujoco>";
    return path;
  };
  char full[300];
  std::snprintf(full, sizeof full, "fullinertia=\"%.17g %.17g %.17g %.17g %.17g %.17g\"", I(0, 0),
                I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  const Model a = load_model(write("full.xml", full));
  const Model b =
      load_model(write("turned.xml", "quat=\"0.7 0.1 0.2 0.3\" diaginertia=\"0.011 0.012 0.004\""));
  Workspace wa(a), wb(b);
  std::mt19937 rng(3);
  const VecX q = random_posture(a, rng);
  mass_matrix(a, wa, q);
  mass_matrix(b, wb, q);
  CHECK(rel_error(wa.Ms, wb.Ms) < 1e-14);
  CHECK(wa.Ms.norm() > 0.01);
}
