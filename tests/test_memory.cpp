// Memory refused up front, one convention (core/workspace/memory.hpp, issue 22): work that
// allocates by input size is estimated first and refused beyond the memory limit with one line, the
// size it needs and how to proceed. The tests set a small --max-memory, so that nothing depends on
// the machine's memory; and the smaller items of the same round (a compact τ table, the condition
// number that overflows, a run too short for SUNDIALS).
#include <sys/resource.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/workspace/memory.hpp"
#include "io/actuation_table.hpp"
#include "sim/integrator.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using nlohmann::json;

TEST_CASE("memory: the refusal is one line with the size, the limit and the way on", "[memory]") {
  CHECK(memory_refusal("x", 1e6, 2e6, "use less").empty());
  CHECK(memory_refusal("the equations of n = 10000 coordinates", 4.4e9, 2e9,
                       "use " + max_memory_option(4.4e9)) ==
        "the equations of n = 10000 coordinates needs 4.4 GB of memory, beyond the memory limit "
        "of 2 GB: use --max-memory 4.9");
  CHECK_THROWS_AS(require_memory("x", 3e3, 1e3, "y"), MemoryRefused);
  CHECK_THAT(out_of_memory_text("running equations"),
             Catch::StartsWith("out of memory while running equations: "));
  // The default: half the available memory, or a process-wide setting.
  set_default_memory_limit(5e3);
  CHECK(memory_limit() == 5e3);
  CHECK(memory_limit(7e3) == 7e3);
  set_default_memory_limit(0);
  CHECK(memory_limit() != 5e3);
}

TEST_CASE("memory: a workspace's estimate holds M^s and its factor", "[memory]") {
  const Model m = load_text(planar_chain(100));
  const double n = m.n();
  CHECK(evaluation_bytes(m) >= dense_bytes(n, n));
  CHECK(evaluation_bytes(m) < 8 * dense_bytes(n, n) + 1e6);
  CHECK(integrator_bytes(m, IntegratorKind::Bdf) >= 2 * dense_bytes(2 * n + 1, 2 * n + 1));
}

TEST_CASE("memory: equations, simulate and check refuse up front beyond --max-memory", "[memory]") {
  Scratch s("memory_refusals");
  const std::string chain = (s.dir / "chain.json").string();
  std::ofstream(chain) << planar_chain(200);
  // equations: M^s (200 x 200) and its printed form need far more than 10 kB.
  Run r = run("equations " + chain + " --max-memory 1e-5");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::StartsWith("femdyn equations: " + chain +
                                      ": the equations of n = 200 coordinates needs "));
  CHECK_THAT(r.out, Catch::Contains(" of memory, beyond the memory limit of 10 kB: use "
                                    "--max-memory "));
  CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  CHECK(run("equations " + chain + " --max-memory 1 --json > /dev/null").code == 0);
  CHECK(run("equations " + chain + " --max-memory -1").code == 2);
  // simulate: bdf's Jacobian, and the --sample-dt times.
  r = run("simulate " + chain + " --t-end 0.01 --integrator bdf --max-memory 1e-4");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::Contains("simulating n = 200 coordinates with bdf needs "));
  CHECK_THAT(r.out, Catch::Contains("or dopri (no Jacobian)"));
  r = run("simulate " + model_path("pendulum.json") +
          " --t-end 1 --sample-dt 1e-7 --max-memory 1e-3");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::Contains("and 1e+07 sample times needs 80 MB of memory, beyond the "
                                    "memory limit of 1 MB"));
  // check: M^s and the 2n eigenproblem.
  r = run("check " + chain + " --max-memory 1e-4");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::Contains("checking n = 200 coordinates needs "));
}

TEST_CASE("memory: a τ table is stored compactly and refused beyond the limit", "[memory]") {
  Scratch s("memory_tau_table");
  const std::string csv = (s.dir / "tau.csv").string();
  {
    std::ofstream out(csv);
    out << "t,theta\n";
    for (int i = 0; i <= 20000; ++i) out << i * 1e-4 << "," << (i % 7) * 0.1 << "\n";
  }
  const Model m = load_model(model_path("pendulum.json"));
  // Read in place: its rows are 8 (n + 1) bytes each, and the table interpolates as before.
  const ActuationTable table(csv, m);
  VecX tau(1);
  table(0.00015, tau);
  CHECK(tau[0] == Approx(0.15));
  CHECK(table.t_last() == Approx(2.0));
  // 20,001 rows of 2 numbers are 320 kB: beyond 100 kB, refused before they are stored.
  try {
    ActuationTable(csv, m, 1e5);
    FAIL("not refused");
  } catch (const MemoryRefused& e) {
    CHECK(std::string(e.what()) ==
          csv +
              ": a table of up to 2e+04 rows of 2 numbers needs 320 kB of memory, beyond the "
              "memory limit of 100 kB: use a table with fewer rows, or --max-memory 0.1 if "
              "that much memory is free");
  }
  const Run r = run("simulate " + model_path("pendulum.json") + " --t-end 1 --tau-csv " + csv +
                    " --max-memory 1e-4");
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::StartsWith("femdyn simulate: " + csv + ": a table of up to 2e+04 rows"));
}

TEST_CASE("an adaptive run too short for SUNDIALS gets femdyn's own message", "[memory]") {
  for (const char* integrator : {"dopri", "bdf"}) {
    const Run r = run("simulate " + model_path("pendulum.json") + " --t-end 1e-300 --integrator " +
                      integrator);
    CHECK(r.code == 2);
    CHECK_THAT(r.out, Catch::Contains(std::string("is too short for ") + integrator +
                                      ": an adaptive integrator needs at least 1e-100 s"));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  CHECK(run("simulate " + model_path("pendulum.json") + " --t-end 1e-300 --integrator rk4").code ==
        0);
}

TEST_CASE("check never prints an overflowing condition number as inf", "[memory]") {
  Scratch s("memory_check_cond");
  json doc = json::parse(planar_chain(3));
  for (int i = 0; i < 3; ++i) doc["bodies"][i]["joint"]["name"] = "j" + std::to_string(i);
  doc["couplings"] =
      json::parse(R"([{"joint": "j2", "follows": "j1", "polynomial": [[1e100, 1]]}])");
  const std::string path = (s.dir / "law.json").string();
  std::ofstream(path) << doc.dump();
  const Run r = run("check " + path + " --states 3");
  CHECK_THAT(r.out, !Catch::Contains("inf"));
  CHECK_THAT(r.out, Catch::Contains("M^s: "));
  CHECK_THAT(r.out, Catch::Contains("keeps no correct digit"));
  CHECK_THAT(r.out, !Catch::Contains("digits of 16"));
  const Run j = run("check " + path + " --states 3 --json");
  CHECK_THAT(j.out, !Catch::Contains("inf"));
}

TEST_CASE("the default memory limit is at most half the address-space limit (ulimit -v)",
          "[memory]") {
  rlimit old{};
  REQUIRE(getrlimit(RLIMIT_AS, &old) == 0);
  rlimit lowered = old;
  lowered.rlim_cur = static_cast<rlim_t>(1) << 50;  // 1 PiB: above anything this process maps
  if (old.rlim_cur != RLIM_INFINITY && old.rlim_cur < lowered.rlim_cur)
    lowered.rlim_cur = old.rlim_cur;
  REQUIRE(setrlimit(RLIMIT_AS, &lowered) == 0);
  const double limit = default_memory_limit();
  setrlimit(RLIMIT_AS, &old);
  CHECK(limit <= 0.5 * static_cast<double>(lowered.rlim_cur));
  CHECK(limit > 0);
}

TEST_CASE("memory: linearize and kinematics estimate up front and refuse beyond the limit",
          "[memory]") {
  // On a 10,000-body tree they ran for a minute to 3.9 GB and then said "out of memory … its
  // estimate was within the memory limit" without making one (issue 45). Each estimate is an
  // upper bound: measured on a 1500-body tree, linearize --json 0.78 GB against 1.75 GB,
  // kinematics --json 0.48 GB against 1.06 GB.
  Scratch s("memory_newer_commands");
  const std::string tree = (s.dir / "tree.json").string();
  std::ofstream(tree)
      << R"({"model": "random_tree", "params": {"seed": 1, "bodies": 10000, "branching": 0.5}})";
  for (const std::string command : {"linearize", "kinematics"}) {
    INFO(command);
    const Run r = run(command + " " + tree + " --json --max-memory 4");
    CHECK(r.code == 1);
    CHECK_THAT(r.out, Catch::StartsWith("femdyn " + command + ": " + tree + ": the ") &&
                          Catch::Contains("n = 10000 coordinates needs ") &&
                          Catch::Contains("beyond the memory limit of 4 GB: use --max-memory "));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
  // Within the limit they run as before.
  CHECK(run("linearize " + model_path("finger.json") + " --max-memory 1 > /dev/null").code == 0);
  CHECK(run("kinematics " + model_path("finger.json") + " --max-memory 1 > /dev/null").code == 0);
}
