// MJCF import (io/mjcf_loader.hpp) against MuJoCo's own compile of the same file
// (validation/mujoco_peer.hpp): M^s, inverse and forward dynamics at random states, femdyn's own
// feature files and public models. Built only when CMake finds MuJoCo (FEMDYN_WITH_MUJOCO).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>

#include "core/dynamics/equations.hpp"
#include "core/joints/passive.hpp"
#include "core/kinematics/sampling.hpp"
#include "models/model_files.hpp"
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
    // femdyn's Coulomb friction (MJCF frictionloss) handed to MuJoCo as an applied force.
    const VecX friction = coulomb_forces(m, qd);
    e.inverse = std::max(e.inverse, rel_error(ws.tau, peer.inverse(q, qd, qdd) - friction));
    REQUIRE(forward_dynamics(m, ws, q, qd, tau).ok);
    e.forward = std::max(e.forward, rel_error(ws.qdd, peer.forward(q, qd, tau + friction)));
  }
  return e;
}

}  // namespace

TEST_CASE("MJCF: femdyn's feature files and public models equal MuJoCo's compile of the same file",
          "[mjcf][mujoco][validation]") {
  for (const char* file :
       {"features.xml", "floating.xml", "dm_control/humanoid.xml", "dm_control/cheetah.xml",
        "dm_control/swimmer.xml", "menagerie/anymal_c.xml"}) {
    INFO(file);
    const Errors e = against_mujoco(mjcf_path(file));
    CHECK(e.mass < 1e-10);
    CHECK(e.inverse < 1e-10);
    CHECK(e.forward < 1e-10);
  }
}

// Mesh geoms (STL binary, OBJ, inline; scale, mass, density, a mesh class): the peer compiles the
// same meshes with exactmeshinertia (MuJoCo 2.2 otherwise weighs a mesh by its equivalent box;
// the meshes here are convex, where legacy and exact agree). MuJoCo holds vertices as float.
TEST_CASE("MJCF: mesh geoms weigh as in MuJoCo's compile of the same file",
          "[mjcf][mujoco][mesh]") {
  const Errors e = against_mujoco(mjcf_path("meshes.xml"));
  CHECK(e.mass < 1e-6);
  CHECK(e.inverse < 1e-6);
  CHECK(e.forward < 1e-6);
  const Run run_ = run("validate " + mjcf_path("meshes.xml") + " --budget 60");
  CHECK(run_.code == 0);
  CHECK_THAT(run_.out, Catch::Contains("the mass of 5 mesh geoms compared to 1e-6"));
}

TEST_CASE("MJCF: femdyn validate compares with MuJoCo's compile of the file, or says why not",
          "[mjcf][cli]") {
  const Run ok = run("validate " + mjcf_path("dm_control/cheetah.xml") + " --json --budget 60");
  CHECK(ok.code == 0);
  CHECK_THAT(ok.out, Catch::Contains("\"mujoco\"") &&
                         Catch::Contains("compared with MuJoCo only") &&
                         Catch::Contains("rotor inertia"));
  // A joint equality (a polynomial coupling) with connect and weld loops: MuJoCo's 7 dofs
  // projected on femdyn's 6 coordinates through G and γ, the spanning trees compared.
  const Run coupled = run("validate " + mjcf_path("loops.xml") + " --budget 60 --json");
  CHECK(coupled.code == 0);
  CHECK_THAT(coupled.out, Catch::Contains("compared through the couplings: MuJoCo's 7 dofs "
                                          "projected on femdyn's 6 coordinates"));
  const nlohmann::json report =  // the JSON after the reader's warning line
      nlohmann::json::parse(coupled.out.substr(coupled.out.find("\n{") + 1));
  REQUIRE(report["max_rel_error"].contains("mujoco"));
  CHECK(report["max_rel_error"]["mujoco"].get<double>() < 1e-10);
  // Tendon equalities (two fixed tendons, and a differential) held as linear couplings.
  const Run tendons = run("validate " + mjcf_path("tendons.xml") + " --budget 60");
  CHECK(tendons.code == 0);
  CHECK_THAT(tendons.out, Catch::Contains("MuJoCo's 6 dofs projected on femdyn's 4"));
}
