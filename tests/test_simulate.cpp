// femdyn simulate end to end: the CSV and its energy balance, a stiff spring that RK4 cannot
// step (clean failure, no NaN written), nothing clobbered or half-written (existing files,
// SIGINT), actuation tables, and the trajectory against Simbody's on a random tree.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "tests/helpers.hpp"
#ifdef FEMDYN_WITH_SIMBODY
#include "validation/validate.hpp"
#endif

using namespace femdyn;
using namespace femdyn::test;
namespace fs = std::filesystem;

namespace {

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  }
};

Csv read_csv(const fs::path& p) {
  Csv c;
  std::ifstream in(p);
  std::string line, cell;
  std::getline(in, line);
  std::istringstream h(line);
  while (std::getline(h, cell, ',')) c.header.push_back(cell);
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::vector<double> row;
    while (std::getline(r, cell, ',')) row.push_back(std::stod(cell));
    c.rows.push_back(std::move(row));
  }
  return c;
}

}  // namespace

TEST_CASE("simulate: CSV columns name the coordinates, energy balance holds row by row",
          "[simulate]") {
  Scratch s("sim_balance");
  // A driven, damped tree: τ from a table, linear between rows.
  std::ofstream(s / "tau.csv")
      << "t,tau_rail,yaw,left_shoulder,left_wrist,right_shoulder,probe_slide\n"
         "0,0.5,0.2,0.1,0,-0.1,0.3\n1,-0.5,0.1,0,0.2,0.1,-0.3\n";
  const Run r = run("simulate " + model_path("branched_tree.json") +
                    " --t-end 1 --rtol 1e-9 --atol 1e-9 --tau-csv " + (s / "tau.csv") +
                    " --q0 0.1,0.2,0.3,0.1,-0.2,0.05 --out " + (s / "traj.csv") + " --json");
  INFO(r.out);
  REQUIRE(r.code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["integrator"] == "dopri");
  CHECK(j["conservative"] == false);
  CHECK(j["steps"].get<long>() > 0);
  CHECK(j["rhs_evals"].get<long>() >= 6 * j["steps"].get<long>());
  const Csv c = read_csv(s / "traj.csv");
  REQUIRE(c.header.size() == 1 + 12 + 4);
  CHECK(c.header[0] == "t");
  CHECK(c.header[1] == "q_rail");
  CHECK(c.header[7] == "qd_rail");
  CHECK(c.header[13] == "kinetic");
  CHECK(c.header[16] == "work");
  CHECK(c.rows.size() == j["rows"].get<std::size_t>());
  CHECK(c.rows.back()[0] == 1.0);
  const int total = c.column("total"), work = c.column("work");
  double balance = 0, scale = 0, max_work = 0;
  for (const auto& row : c.rows) {
    balance = std::max(balance, std::abs(row[total] - c.rows[0][total] - row[work]));
    scale = std::max(scale, std::abs(row[total]));
    max_work = std::max(max_work, std::abs(row[work]));
  }
  INFO("balance " << balance << " J, scale " << scale << " J, |W| up to " << max_work << " J");
  CHECK(max_work > 1e-3 * scale);
  CHECK(balance < 1e-7 * scale);
  CHECK(std::abs(j["energy_balance_error"].get<double>() - balance) <= 1e-12 * scale);
}

TEST_CASE("simulate: a 1e4 rad/s spring makes RK4 at 1e-3 s diverge cleanly, BDF runs it",
          "[simulate]") {
  Scratch s("sim_stiff");
  std::ofstream(s / "spring.json") << R"({"name": "stiff spring", "gravity": [0, 0, 0],
    "bodies": [{"name": "arm", "parent": "world", "joint": {"name": "theta", "type": "revolute",
    "axis": [0, 1, 0], "spring": {"stiffness": 1e8}}, "elements": [{"type": "lumped_point",
    "node": [1, 0, 0], "mass": 1.0}]}]})";
  Run r = run("simulate " + (s / "spring.json") +
              " --t-end 1 --integrator rk4 --dt 1e-3 --q0 0.1 --out " + (s / "rk4.csv"));
  INFO(r.out);
  CHECK(r.code == 1);
  CHECK_THAT(r.out, Catch::Contains("femdyn simulate: ") && Catch::Contains(": at t = ") &&
                        Catch::Contains("the solution diverges") &&
                        Catch::Contains("stability limit") && Catch::Contains("or dopri"));
  const std::string text = read_file(s / "rk4.csv");
  REQUIRE_FALSE(text.empty());
  CHECK(text.find("nan") == std::string::npos);
  CHECK(text.find("inf") == std::string::npos);
  r = run("simulate " + (s / "spring.json") +
          " --t-end 0.01 --integrator bdf --rtol 1e-10 --atol 1e-12 --q0 0.1 --out " +
          (s / "bdf.csv"));
  REQUIRE(r.code == 0);
  const Csv c = read_csv(s / "bdf.csv");
  double err = 0;
  for (const auto& row : c.rows)
    err = std::max(err, std::abs(row[1] - 0.1 * std::cos(1e4 * row[0])));
  INFO("BDF against θ0 cos ωt: " << err);
  CHECK(err < 1e-5);
}

TEST_CASE("simulate: existing files kept without --force, SIGINT leaves the old file whole",
          "[simulate]") {
  Scratch s("sim_files");
  const std::string out = s / "traj.csv";
  std::ofstream(out) << "old content\n";
  Run r = run("simulate " + model_path("pendulum.json") + " --t-end 0.1 --out " + out);
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn simulate: --out " + out + ": exists (use --force to replace it)\n");
  CHECK(read_file(out) == "old content\n");
  // A long run interrupted after 1 s: exit 130, the old file intact, no temporary file left.
  r = run_shell("timeout --preserve-status -s INT 1 " + std::string(FEMDYN_BINARY) + " simulate " +
                model_path("hand.json") +
                " --t-end 1000 --integrator rk4 --dt 1e-5 --max-steps 1e9 --every 10000 --force "
                "--out " +
                out);
  INFO(r.out);
  CHECK(r.code == 130);
  CHECK_THAT(r.out, Catch::Contains("interrupted at t = ") && Catch::Contains("was not written"));
  CHECK(read_file(out) == "old content\n");
  CHECK(s.files() == 1);
  // With --force a finished run replaces it.
  r = run("simulate " + model_path("pendulum.json") + " --t-end 0.1 --q0 1 --force --out " + out);
  CHECK(r.code == 0);
  CHECK(read_file(out).rfind("t,q_theta,qd_theta,kinetic,potential,total,work\n", 0) == 0);
  CHECK(s.files() == 1);
}

TEST_CASE("simulate: bad options and bad actuation tables get one line", "[simulate]") {
  Scratch s("sim_bad");
  const std::string pend = model_path("pendulum.json");
  Run r = run("simulate " + pend + " --t-end 1 --integrator dopri --dt 1e-3");
  CHECK(r.code == 2);
  CHECK(r.out ==
        "femdyn simulate: --dt sets the step of rk4 and euler; dopri is adaptive: use --rtol and "
        "--atol\n");
  r = run("simulate " + pend + " --t-end 1 --rtol -1");
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn simulate: --rtol: the relative tolerance must be in (0, 1), got -1\n");
  r = run("simulate " + pend + " --t-end 1 --integrator rk5");
  CHECK(r.code == 2);
  CHECK(r.out == "femdyn simulate: --integrator: 'rk5' is not one of rk4, euler, dopri, bdf\n");
  r = run("simulate " + pend);
  CHECK(r.code == 2);
  std::ofstream(s / "tau.csv") << "t,elbow\n0,1\n";
  r = run("simulate " + pend + " --t-end 1 --tau-csv " + (s / "tau.csv"));
  CHECK(r.code == 1);
  CHECK(r.out == "femdyn simulate: " + (s / "tau.csv") +
                     ":1: column 2 'elbow' is not a coordinate of single pendulum\n");
  std::ofstream(s / "tau2.csv") << "t,theta\n0,1\n0.5,x\n";
  r = run("simulate " + pend + " --t-end 1 --tau-csv " + (s / "tau2.csv"));
  CHECK(r.out == "femdyn simulate: " + (s / "tau2.csv") + ":3: column 2: 'x' is not a number\n");
  std::ofstream(s / "tau3.csv") << "t,theta\n0,1\n0.5,2\n";
  r = run("simulate " + pend + " --t-end 1 --tau-csv " + (s / "tau3.csv"));
  CHECK(r.code == 2);
  CHECK_THAT(r.out, Catch::Contains("covers t in [0, 0.5] s; it must cover [0, 1] s"));
}

#ifdef FEMDYN_WITH_SIMBODY
TEST_CASE("simulate matches Simbody's trajectory on a random tree", "[simulate][validation]") {
  Scratch s("sim_simbody");
  std::ofstream(s / "tree.json") << random_tree_json(11, 7, 0.5, true);
  const Model m = load_model(s / "tree.json");
  std::mt19937 rng(4);
  const VecX q0 = random_uniform(m.n(), 0.5, rng), qd0 = random_uniform(m.n(), 1.0, rng);
  const auto list = [](const VecX& v) {
    std::ostringstream o;
    o.precision(17);
    for (Eigen::Index i = 0; i < v.size(); ++i) o << (i ? "," : "") << v[i];
    return o.str();
  };
  const Run r =
      run("simulate " + (s / "tree.json") + " --t-end 0.5 --rtol 1e-11 --atol 1e-12 --q0 " +
          list(q0) + " --qd0 " + list(qd0) + " --every 5 --out " + (s / "traj.csv"));
  INFO(r.out);
  REQUIRE(r.code == 0);
  const Csv c = read_csv(s / "traj.csv");
  std::vector<double> times;
  for (const auto& row : c.rows) times.push_back(row[0]);
  validation::SimbodyTwin twin(validation::twin_model(m));
  REQUIRE(twin.can_simulate());
  const auto sim = twin.simulate(q0, qd0, times, 1e-12);
  REQUIRE(sim.size() == c.rows.size());
  const int n = m.n();
  double err = 0, energy_gap = 0;
  for (std::size_t k = 0; k < sim.size(); ++k) {
    for (int i = 0; i < n; ++i) {
      err = std::max(err, std::abs(c.rows[k][1 + i] - sim[k].theta[i]));
      err = std::max(err, std::abs(c.rows[k][1 + n + i] - sim[k].theta_dot[i]));
    }
    // Energies agree up to their zero: compare changes since t = 0.
    energy_gap = std::max(energy_gap, std::abs((c.rows[k][2 * n + 3] - c.rows[0][2 * n + 3]) -
                                               (sim[k].energy - sim[0].energy)));
  }
  INFO(c.rows.size() << " rows; max state difference " << err << ", energy change gap "
                     << energy_gap);
  CHECK(err < 1e-7);
  CHECK(energy_gap < 1e-8);
}
#endif
