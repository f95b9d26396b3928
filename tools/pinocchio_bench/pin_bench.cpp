// A peer timing outside femdyn's build (tools/pinocchio_bench/README.md): Pinocchio 3's `aba`
// and `computeABADerivatives` (q̈, ∂q̈/∂q, ∂q̈/∂v and M⁻¹, as femdyn's `femdyn/derivatives/M`) on
// the URDF robots femdyn_bench times, fixed and on a free-flyer base, with Google Benchmark.
//
//   pin_bench --robots=DIR [google-benchmark flags]   time (DIR holds iiwa, hyq, atlas .urdf)
//   pin_bench --robots=DIR --sanity                   q̈ and the derivatives' norms at two fixed
//                                                     states, with Pinocchio's own checks

#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "pinocchio/algorithm/aba-derivatives.hpp"
#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/joint-configuration.hpp"
#include "pinocchio/multibody/joint/joint-free-flyer.hpp"
#include "pinocchio/parsers/urdf.hpp"

namespace pin = pinocchio;

static std::string g_robots_dir = "tests/robots";
static const char *kRobots[] = {"iiwa", "hyq", "atlas"};
static const int kNumStates = 8;
static const unsigned kSeed = 12345u;

struct Case {
  std::string name;  // e.g. "atlas" or "atlas_floating"
  pin::Model model;
  std::vector<Eigen::VectorXd> qs, vs, taus;
};

static pin::Model loadModel(const std::string &robot, bool floating) {
  const std::string path = g_robots_dir + "/" + robot + ".urdf";
  pin::Model model;
  if (floating)
    pin::urdf::buildModel(path, pin::JointModelFreeFlyer(), model);
  else
    pin::urdf::buildModel(path, model);
  return model;
}

static std::unique_ptr<Case> makeCase(const std::string &robot, bool floating) {
  std::unique_ptr<Case> c(new Case);
  c->name = floating ? robot + "_floating" : robot;
  c->model = loadModel(robot, floating);
  const pin::Model &m = c->model;

  // Position bounds for randomConfiguration: URDF joint limits for the revolute
  // joints; for the free-flyer translation use [-1, 1] (quaternion part is drawn
  // uniformly on S^3 regardless of bounds).
  Eigen::VectorXd lo = m.lowerPositionLimit, hi = m.upperPositionLimit;
  if (floating) {
    lo.head<7>().setConstant(-1.0);
    hi.head<7>().setConstant(1.0);
  }
  std::srand(kSeed);  // Pinocchio's randomConfiguration uses std::rand
  std::mt19937 gen(kSeed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int k = 0; k < kNumStates; ++k) {
    Eigen::VectorXd q = pin::randomConfiguration(m, lo, hi);
    Eigen::VectorXd v(m.nv), tau(m.nv);
    for (int i = 0; i < m.nv; ++i) v[i] = U(gen);
    for (int i = 0; i < m.nv; ++i) tau[i] = U(gen);
    c->qs.push_back(q);
    c->vs.push_back(v);
    c->taus.push_back(tau);
  }
  return c;
}

// aba in either of Pinocchio 3's conventions (LOCAL, its default, or WORLD).
static void BM_aba(benchmark::State &st, const Case *c, pin::Convention convention) {
  pin::Data data(c->model);
  int k = 0;
  for (auto _ : st) {
    const Eigen::VectorXd &a = pin::aba(c->model, data, c->qs[k], c->vs[k], c->taus[k], convention);
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
    k = (k + 1) & (kNumStates - 1);
  }
  st.counters["nv"] = c->model.nv;
}

static void BM_aba_derivatives(benchmark::State &st, const Case *c) {
  pin::Data data(c->model);
  int k = 0;
  for (auto _ : st) {
    pin::computeABADerivatives(c->model, data, c->qs[k], c->vs[k], c->taus[k]);
    benchmark::DoNotOptimize(data.ddq.data());
    benchmark::DoNotOptimize(data.ddq_dq.data());
    benchmark::DoNotOptimize(data.ddq_dv.data());
    benchmark::DoNotOptimize(data.Minv.data());
    benchmark::ClobberMemory();
    k = (k + 1) & (kNumStates - 1);
  }
  st.counters["nv"] = c->model.nv;
}

static int runSanity() {
  std::printf("# Pinocchio %s sanity, robots dir %s\n", PINOCCHIO_VERSION, g_robots_dir.c_str());
  std::printf("# fixed base; gravity = model.gravity; v = 0.2*ones; tau = 0\n");
  std::printf("# state A: q_i = 0.1*(i+1)            (i = 0..nv-1, Pinocchio joint order)\n");
  std::printf("# state B: q_i = 0.1*((i mod 10)+1)\n");
  for (const char *robot : kRobots) {
    pin::Model model = loadModel(robot, false);
    pin::Data data(model);
    const int nv = model.nv;
    std::printf("\n== %s: nq = %d, nv = %d, gravity = (%g, %g, %g)\n", robot, model.nq, nv,
                model.gravity.linear()[0], model.gravity.linear()[1], model.gravity.linear()[2]);
    std::printf("joint order (idx_v: name):");
    for (pin::JointIndex j = 1; j < (pin::JointIndex)model.njoints; ++j)
      std::printf(" %d:%s", model.joints[j].idx_v(), model.names[j].c_str());
    std::printf("\n");
    for (int variant = 0; variant < 2; ++variant) {
      Eigen::VectorXd q(nv), v = Eigen::VectorXd::Constant(nv, 0.2),
                             tau = Eigen::VectorXd::Zero(nv);
      for (int i = 0; i < nv; ++i) q[i] = variant == 0 ? 0.1 * (i + 1) : 0.1 * ((i % 10) + 1);
      const Eigen::VectorXd a = pin::aba(model, data, q, v, tau);
      pin::computeABADerivatives(model, data, q, v, tau);
      Eigen::MatrixXd Minv = data.Minv;
      Minv.triangularView<Eigen::StrictlyLower>() = Minv.transpose();
      std::printf("-- state %c\n", variant == 0 ? 'A' : 'B');
      std::printf("qdd (aba)          =");
      for (int i = 0; i < nv; ++i) std::printf(" %.10g", a[i]);
      std::printf("\nqdd (derivs ddq)   max|diff vs aba| = %.3g\n",
                  (data.ddq - a).cwiseAbs().maxCoeff());
      std::printf("||ddq_dq||_F = %.10g\n", data.ddq_dq.norm());
      std::printf("||ddq_dv||_F = %.10g\n", data.ddq_dv.norm());
      std::printf("||Minv||_F   = %.10g   (symmetrized; Minv(0,0) = %.10g)\n", Minv.norm(),
                  Minv(0, 0));
      // Self-checks (independent of the timed code paths): Minv vs inverse of CRBA M,
      // and central finite differences of aba for ddq_dq / ddq_dv.
      {
        pin::Data d2(model);
        pin::crba(model, d2, q);
        Eigen::MatrixXd M = d2.M;
        M.triangularView<Eigen::StrictlyLower>() = M.transpose();
        const double e_minv = (Minv * M - Eigen::MatrixXd::Identity(nv, nv)).cwiseAbs().maxCoeff();
        const double h = 1e-6;
        Eigen::MatrixXd Jq(nv, nv), Jv(nv, nv);
        for (int j = 0; j < nv; ++j) {
          Eigen::VectorXd dq = Eigen::VectorXd::Zero(nv);
          dq[j] = h;
          Eigen::VectorXd ap = pin::aba(model, d2, q + dq, v, tau);
          Eigen::VectorXd am = pin::aba(model, d2, q - dq, v, tau);
          Jq.col(j) = (ap - am) / (2 * h);
          ap = pin::aba(model, d2, q, v + dq, tau);
          am = pin::aba(model, d2, q, v - dq, tau);
          Jv.col(j) = (ap - am) / (2 * h);
        }
        std::printf(
            "check: max|Minv*M - I| = %.3g, max|ddq_dq - FD| = %.3g, max|ddq_dv - FD| = %.3g\n",
            e_minv, (data.ddq_dq - Jq).cwiseAbs().maxCoeff(),
            (data.ddq_dv - Jv).cwiseAbs().maxCoeff());
      }
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  bool sanity = false;
  std::vector<char *> rest;
  rest.push_back(argv[0]);
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--sanity") == 0)
      sanity = true;
    else if (std::strncmp(argv[i], "--robots=", 9) == 0)
      g_robots_dir = argv[i] + 9;
    else
      rest.push_back(argv[i]);
  }
  if (sanity) return runSanity();

  int bargc = (int)rest.size();
  benchmark::Initialize(&bargc, rest.data());
  if (benchmark::ReportUnrecognizedArguments(bargc, rest.data())) return 1;

  std::vector<std::unique_ptr<Case>> cases;
  for (const char *robot : kRobots)
    for (bool floating : {false, true}) cases.push_back(makeCase(robot, floating));

  for (const auto &c : cases)
    benchmark::RegisterBenchmark(("pinocchio/aba/" + c->name).c_str(), BM_aba, c.get(),
                                 pin::Convention::LOCAL);
  for (const auto &c : cases)
    benchmark::RegisterBenchmark(("pinocchio/aba_world/" + c->name).c_str(), BM_aba, c.get(),
                                 pin::Convention::WORLD);
  for (const auto &c : cases)
    benchmark::RegisterBenchmark(("pinocchio/aba_derivatives/" + c->name).c_str(),
                                 BM_aba_derivatives, c.get());

  benchmark::AddCustomContext("pinocchio_version", PINOCCHIO_VERSION);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
