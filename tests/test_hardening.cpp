// Hostile input (issue 12): every case ends in a one-line error naming the place, or succeeds;
// never a crash, a hang, a foreign exception text, or NaN printed as an answer.
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "io/urdf_loader.hpp"
#include "tests/helpers.hpp"
#include "validation/scaling_models.hpp"
#include "validation/twin.hpp"

using namespace femdyn;
using namespace femdyn::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// A fresh directory per process (ctest runs test cases in parallel processes).
fs::path scratch() {
  const fs::path dir = fs::temp_directory_path() / ("femdyn_hardening_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string load_error(const std::string& path) {
  try {
    load_model(path);
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(loaded)";
}

// models/pendulum.json as JSON, to be mutated.
json pendulum_model() { return json::parse(read_file(model_path("pendulum.json"))); }

}  // namespace

TEST_CASE("a FIFO or a device or a directory is refused at once", "[hardening]") {
  const fs::path fifo = scratch() / "model.json";
  fs::remove(fifo);
  REQUIRE(mkfifo(fifo.c_str(), 0600) == 0);
  // Without a writer, reading a FIFO would block for ever: it is refused before any read.
  CHECK(load_error(fifo) ==
        fifo.string() +
            ": is not a regular file (a FIFO, device or socket): femdyn reads files only");
  fs::remove(fifo);
  CHECK(load_error("/dev/zero") ==
        "/dev/zero: is not a regular file (a FIFO, device or socket): femdyn reads files only");
  CHECK(load_error(scratch().string()) == scratch().string() + ": is a directory, not a file");
  CHECK(load_error("/dev/zero.urdf").find("cannot open file") != std::string::npos);
}

TEST_CASE("a file over the size limit is refused before it is read", "[hardening]") {
  const fs::path big = scratch() / "big.json";
  { std::ofstream(big.string()); }
  fs::resize_file(big, (256u << 20) + 1);  // sparse: no 256 MiB written
  CHECK_THAT(load_error(big), Catch::Contains("bytes: more than the limit of 268435456 bytes"));
  fs::remove(big);
}

TEST_CASE("JSON nested deeper than the limit is refused without recursion", "[hardening]") {
  for (const int depth : {65, 100000}) {
    INFO(depth);
    const std::string text =
        "{\"name\": " + std::string(depth, '[') + std::string(depth, ']') + "}";
    CHECK(text_error(text) == "test: JSON nested deeper than 64 levels (femdyn's limit)");
  }
}

TEST_CASE("out-of-range numbers are refused naming the field", "[hardening]") {
  json g = pendulum_model();
  g["gravity"] = {0, 0, -1e308};
  CHECK(text_error(g.dump()) ==
        "test: /gravity: gravity -1e+308 is out of range (|x| ≤ 1e100: "
        "beyond it the equations' products overflow double precision)");
  json k = pendulum_model();
  k["bodies"][0]["joint"]["spring"] = {{"stiffness", 1e308}};
  CHECK_THAT(text_error(k.dump()),
             Catch::StartsWith("test: /bodies/0/joint: stiffness 1e+308 is out of range"));
  json m = pendulum_model();
  m["bodies"][0]["elements"][0]["mass"] = 1e308;
  CHECK_THAT(text_error(m.dump()),
             Catch::StartsWith(
                 "test: /bodies/0/elements/0: element mass matrix entry 1e+308 is out of range"));
  // The same from the command line: one line, exit 1 or 2, no NaN printed.
  const Run cli = run("equations " + model_path("finger.json") + " --gravity 0,0,1e308");
  CHECK(cli.code != 0);
  CHECK(cli.out.find('\n') == cli.out.size() - 1);
  const Run qd = run("equations " + model_path("finger.json") + " --qd 1e200,0,0,0");
  CHECK(qd.code == 2);
  CHECK_THAT(qd.out, Catch::Contains("--qd: '1e200' is out of range"));
  // Underflow is not out of range: 1e-400 is read as its nearest double (0).
  CHECK(run("equations " + model_path("pendulum.json") + " --q 1e-400").code == 0);
  // Integers beyond int are refused before any cast.
  const std::string finger = model_path("finger.json");
  const Run states = run("compare " + finger + " " + finger + " --states 3e9");
  CHECK(states.code == 2);
  CHECK(states.out == "femdyn compare: --states expects one integer <= 2147483647\n");
  // Gravity given in place of the file's is named as such, not as the file's /gravity.
  LoadOptions options;
  options.gravity = Vec3(0, 0, 1e200);
  options.gravity_source = "--gravity";
  const std::string path = model_path("pendulum.json");
  CHECK_THROWS_WITH(load_model(path, options),
                    Catch::StartsWith(path + ": --gravity: gravity 1e+200 is out of range"));
}

TEST_CASE("a τ table (--tau-csv) is held to the 1e100 limit like --tau", "[hardening]") {
  const fs::path dir = scratch();
  const std::string pend = model_path("pendulum.json"), csv = (dir / "tau.csv").string();
  const auto simulate = [&](const std::string& rows) {
    std::ofstream(csv) << "t,theta\n" << rows;
    return run("simulate " + pend + " --t-end 1 --tau-csv " + csv);
  };
  const std::string limit =
      " is out of range (|x| ≤ 1e100: beyond it the equations' products overflow double "
      "precision)\n";
  Run r = simulate("0,1\n1,1e200\n");  // τ: file, line, column and the value
  CHECK(r.code == 1);
  CHECK(r.out == "femdyn simulate: " + csv + ":3: column 2: 1e+200" + limit);
  r = simulate("0,1\n1,-1e400\n");  // beyond double: the text as written
  CHECK(r.code == 1);
  CHECK(r.out == "femdyn simulate: " + csv + ":3: column 2: '-1e400'" + limit);
  r = simulate("0,1\n1e200,1\n");  // the time column too
  CHECK(r.code == 1);
  CHECK(r.out == "femdyn simulate: " + csv + ":3: column 1: 1e+200" + limit);
  // The same limit as --tau's, and nothing stricter: 1e100 itself and an underflow are read.
  CHECK_THAT(run("simulate " + pend + " --t-end 1 --tau 1e101").out,
             Catch::Contains("--tau: '1e101'" + limit.substr(0, limit.size() - 1)));
  r = simulate("0,1e-400\n1,-1e100\n");
  CHECK_THAT(r.out, !Catch::Contains(csv + ":"));  // (the run may overflow; the table is read)
  r = simulate("0,1e-400\n1,-0.5\n");
  CHECK(r.code == 0);
  fs::remove_all(dir);
}

TEST_CASE("names with control characters are refused and user text is echoed escaped",
          "[hardening]") {
  json j = pendulum_model();
  j["bodies"][0]["name"] = "arm\x1b[31m";
  const std::string e = text_error(j.dump());
  CHECK(e ==
        "test: /bodies/0/name: body name 'arm\\x1b[31m' contains a control character "
        "(names must be printable)");
  json p = pendulum_model();
  p["bodies"][0]["parent"] = "w\x1b]0;title\x07";
  CHECK(text_error(p.dump()) ==
        "test: /bodies/0/parent: unknown parent body 'w\\x1b]0;title\\x07'");
  json c1 = pendulum_model();  // U+009B, the one-byte CSI of 8-bit terminals
  c1["bodies"][0]["joint"]["name"] =
      "hinge\xc2\x9b"
      "2J";
  CHECK_THAT(text_error(c1.dump()),
             Catch::Contains("'hinge\\xc2\\x9b2J' contains a control character"));
  // Constraint and spring names reach info, check and the reports too (issue 45).
  json loop = json::parse(read_file(model_path("five_bar.json")));
  loop["constraints"][0]["name"] = "end\x1b[31m";
  CHECK(text_error(loop.dump()) ==
        "test: /constraints/0/name: constraint name 'end\\x1b[31m' contains a control character "
        "(names must be printable)");
  json spring = pendulum_model();
  spring["springs"] = json::parse(R"([{"a": "world", "b": "bob", "stiffness": 1}])");
  spring["springs"][0]["name"] = "k\x07";
  CHECK_THAT(text_error(spring.dump()),
             Catch::Contains("/springs/0/name: spring name 'k\\x07' contains a control character"));
  const Run cli =
      run("equations " + model_path("finger.json") + " --q \"$(printf '0,0,0,1\\033[2J')\"");
  CHECK(cli.code == 2);
  CHECK(cli.out.find('\x1b') == std::string::npos);
}

TEST_CASE("a 100000-body chain is compiled or refused with a message and never crashes",
          "[hardening]") {
  // The compile passes are linear in the bodies (no recursion, no search over all nodes or
  // bodies). This chain is 10 km of 0.1 m links: the leaf's M^s(a, a) is ~1e-14 of the root's,
  // which femdyn reports as singular to double precision.
  const std::string e = text_error(planar_chain(100000));
  CHECK_THAT(e, Catch::Contains("is singular to double precision: coordinate 'b9999"));
  // 10,000 links compile.
  CHECK(load_text(planar_chain(10000)).n() == 10000);
}

TEST_CASE("deep trees and long coupling chains compile on a small stack", "[hardening]") {
  // Compile walks the tree and resolves couplings with explicit stacks. Proved on a thread with
  // a 256 KiB stack: a recursion per body or per coupling (≥ 100 bytes a frame) would overflow it
  // at 5,000. Joint names default to the body names; every joint follows the previous one.
  json j = json::parse(planar_chain(5000));
  json couplings = json::array();
  for (int i = 1; i < 5000; ++i)
    couplings.push_back(
        {{"joint", "b" + std::to_string(i)}, {"follows", "b" + std::to_string(i - 1)}});
  j["couplings"] = couplings;
  struct Job {
    std::string text;
    int n = -1;
    std::string error;
  } job{j.dump()};
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, 256 * 1024);
  pthread_t thread;
  const auto body = [](void* p) -> void* {
    auto& job = *static_cast<Job*>(p);
    try {
      job.n = load_text(job.text).n();
    } catch (const std::exception& e) {
      job.error = e.what();
    }
    return nullptr;
  };
  REQUIRE(pthread_create(&thread, &attr, body, &job) == 0);
  pthread_join(thread, nullptr);
  pthread_attr_destroy(&attr);
  INFO(job.error);
  CHECK(job.n == 1);  // one coordinate drives all 5,000 joints
}

TEST_CASE("huge joint limits give finite sample postures", "[hardening]") {
  json j = pendulum_model();
  j["bodies"][0]["joint"]["limits"] = {-1e308, 1e308};
  const Model m = load_text(j.dump());
  std::mt19937 rng(1);
  for (int k = 0; k < 100; ++k) {
    const VecX q = random_posture(m, rng);
    CHECK(std::abs(q[0]) <= 3.15);
  }
  j["bodies"][0]["joint"]["limits"] = {10, 1e308};  // disjoint from ±π: the first 2π of them
  const Model n = load_text(j.dump());
  const double q = random_posture(n, rng)[0];
  CHECK((q >= 10 && q <= 10 + 6.3));
}

TEST_CASE("Simbody's refusals reach the user as one line naming the body", "[hardening]") {
  validation::TwinModel t;
  validation::TwinBody b;
  b.name = "bad";
  b.joint = validation::TwinBody::Joint::Revolute;
  b.theta = 0;
  b.mass = 1;
  b.inertia_origin = Mat3::Identity();
  b.inertia_origin(0, 1) = b.inertia_origin(1, 0) = std::nan("");  // Simbody asserts no NaN
  t.bodies.push_back(b);
  t.theta_body = {0};
  t.C = MatX::Identity(1, 1).sparseView();
  t.theta0 = VecX::Zero(1);
  try {
    validation::SimbodyTwin twin(t);
    FAIL("Simbody accepted a NaN inertia");
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    CHECK_THAT(what, Catch::StartsWith("Simbody refuses body 'bad': "));
    CHECK(what.find('\n') == std::string::npos);
  }
}

TEST_CASE("outputs never clobber an input or an existing file without --force", "[hardening]") {
  const fs::path dir = scratch();
  const fs::path urdf = dir / "robot.urdf", json_out = dir / "robot.json";
  fs::copy_file(model_path("urdf/hand16.urdf"), urdf, fs::copy_options::overwrite_existing);
  fs::remove(json_out);
  const std::string before = [&] {
    std::ifstream in(urdf);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  const Run self = run("import " + urdf.string() + " -o " + urdf.string());
  CHECK(self.code == 2);
  CHECK(self.out == "femdyn import: -o " + urdf.string() + " is the model file itself\n");
  const std::string after = [&] {
    std::ifstream in(urdf);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  CHECK(after == before);
  CHECK(run("import " + urdf.string() + " -o " + json_out.string()).code == 0);
  const Run again = run("import " + urdf.string() + " -o " + json_out.string());
  CHECK(again.out ==
        "femdyn import: " + json_out.string() + ": exists (use --force to replace it)\n");
  CHECK(run("import " + urdf.string() + " -o " + json_out.string() + " --force").code == 0);
  // A device is never renamed over, even with --force (as root, that would replace /dev/full).
  const Run dev = run("import " + urdf.string() + " -o /dev/full --force");
  CHECK(dev.out ==
        "femdyn import: /dev/full: is not a regular file (femdyn writes regular files only)\n");
  fs::remove(urdf);
  fs::remove(json_out);
}

TEST_CASE("the D tensor is refused before allocating past the limit", "[hardening]") {
  const fs::path big = scratch() / "tree300.json";
  std::ofstream(big.string())
      << R"({"model": "random_tree", "params": {"seed": 1, "bodies": 300}})";
  const Run r = run("equations " + big.string() + " --tensor");
  CHECK(r.code == 2);
  CHECK_THAT(r.out, Catch::StartsWith("femdyn equations: --tensor: D needs "));
  CHECK_THAT(r.out, Catch::Contains("the limit is 2e+07"));
  fs::remove(big);
}

TEST_CASE("correlation-table integers are range-checked before narrowing", "[hardening]") {
  Json doc = model_document(model_path("finger_paper.json"));
  REQUIRE(doc.contains("correlation_table"));
  const auto with_entry = [&](const Json& value) {
    Json d = doc;
    d["correlation_table"]["rows"][0][5] = value;
    return text_error(d.dump());
  };
  CHECK(
      with_entry(std::int64_t{1} << 31) ==
      "test: /correlation_table/rows/0/5: DOF number 2147483648 is out of range (0 to 2147483647)");
  CHECK(with_entry(std::uint64_t{1} << 63) ==
        "test: /correlation_table/rows/0/5: DOF number 9223372036854775808 is out of range (0 to "
        "2147483647)");
  CHECK(with_entry(-1) ==
        "test: /correlation_table/rows/0/5: DOF number -1 is out of range (0 to 2147483647)");
  CHECK_THAT(with_entry(999999),
             Catch::Contains("system DOF number 999999 exceeds the 48 entries"));
}

TEST_CASE("an interrupted simulate leaves the old output file intact", "[hardening]") {
  const fs::path dir = scratch() / "sigint";
  fs::create_directories(dir);
  const fs::path out = dir / "traj.csv";
  std::ofstream(out.string()) << "old\n";
  // A run of a simulated hour at a 1 µs step takes far longer than the 1 s before SIGINT.
  const Run r = run_shell(
      "sh -c '" + std::string(FEMDYN_BINARY) + " simulate " + model_path("finger.json") +
      " --t-end 3600 --integrator rk4 --dt 1e-6 --max-steps 1e10 --every 1000000 --out " +
      out.string() + " --force & pid=$!; sleep 1; kill -INT $pid; wait $pid; echo exit=$?'");
  INFO(r.out);
  CHECK(r.out.find("exit=130") != std::string::npos);  // stopped by the signal, as documented
  std::ifstream in(out.string());
  CHECK(std::string(std::istreambuf_iterator<char>(in), {}) == "old\n");
  int files = 0;
  for ([[maybe_unused]] const auto& f : fs::directory_iterator(dir)) ++files;
  CHECK(files == 1);  // no temporary file left beside it
  fs::remove_all(dir);
}

TEST_CASE("SIGINT ends an adaptive simulate inside a long span between outputs at once",
          "[hardening]") {
  // One output every 1e6 s: the old check between outputs answered only after minutes of work.
  // The stop is now asked inside the steps (every 20 ms at most): exit 130 within a second.
  for (const char* integrator : {"dopri", "bdf"}) {
    INFO(integrator);
    const Run r = run_shell(
        "sh -c '" + std::string(FEMDYN_BINARY) + " simulate " + model_path("finger.json") +
        " --t-end 1e9 --integrator " + integrator +
        " --qd0 1,1,1,1 --sample-dt 1e6 & pid=$!; sleep 1; s=$(date +%s%N); kill -INT $pid; "
        "wait $pid; echo exit=$? ms=$(( ($(date +%s%N) - s) / 1000000 ))'");
    INFO(r.out);
    CHECK(r.out.find("exit=130") != std::string::npos);
    const std::size_t at = r.out.find("ms=");
    REQUIRE(at != std::string::npos);
    CHECK(std::stol(r.out.substr(at + 3)) < 1000);
  }
}

TEST_CASE("track streams its --csv table and an interrupted track leaves no file", "[hardening]") {
  // The table grows on disk while the run lasts (it was built in memory: 1 GB and growing at
  // 10 million steps); SIGINT ends it with exit 130, the file not written, no temporary left.
  const fs::path dir = scratch() / "track_stream";
  fs::create_directories(dir);
  const fs::path out = dir / "table.csv";
  const Run r =
      run_shell("sh -c '" + std::string(FEMDYN_BINARY) + " track " + model_path("finger.json") +
                " --to 0.3,0.5,0.4,0.3 --steps 10000000 --csv " + out.string() +
                " & pid=$!; sleep 1.5; echo bytes=$(find " + dir.string() +
                " -type f -exec cat {} + | wc -c); kill -INT $pid; wait $pid; echo exit=$?' 2>&1");
  INFO(r.out);
  CHECK(r.out.find("exit=130") != std::string::npos);
  CHECK_THAT(r.out, Catch::Contains("femdyn track: interrupted at t = ") &&
                        Catch::Contains("was not written"));
  const std::size_t at = r.out.find("bytes=");
  REQUIRE(at != std::string::npos);
  CHECK(std::stol(r.out.substr(at + 6)) > 100000);  // rows already on disk, before the end
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

// Issue 22: readers and compile linear in n. The inputs are generated here; their times are
// measured in femdyn_bench (docs/performance.md), never asserted.
TEST_CASE("a JSON array of 1,000,000 objects is read, and as bodies refused by count",
          "[hardening][scale]") {
  std::string objects;
  objects.reserve(8'000'000);
  for (int i = 0; i < 1'000'000; ++i) objects += i ? ",{\"a\":1}" : "{\"a\":1}";
  // Parsed whole (nlohmann's plain parser, linear), then refused by the first check after it.
  CHECK(text_error(R"({"stuff": [)" + objects + "]}") == "test: /stuff: unknown key 'stuff'");
  // As bodies: counted before the text is parsed.
  CHECK(text_error(R"({"bodies": [)" + objects + "]}") ==
        "test: /bodies: 1000000 bodies: more than femdyn's limit of 200000");
  // The count is of the top-level "bodies" only, wherever it is, and strings cannot fool it.
  CHECK(text_error(R"({"name": "\"bodies\": [{},{}]", "x": {"bodies": [)" + objects + "]}}") ==
        "test: /x: unknown key 'x'");
  // The same from a file, from the command line and through femdyn.load (load_model).
  const fs::path file = scratch() / "million.json";
  std::ofstream(file.string()) << R"({"bodies": [)" << objects << "]}";
  CHECK(load_error(file.string()) ==
        file.string() + ": /bodies: 1000000 bodies: more than femdyn's limit of 200000");
  const Run cli = run("info " + file.string());
  CHECK(cli.code == 1);
  CHECK(cli.out == "femdyn info: " + file.string() +
                       ": /bodies: 1000000 bodies: more than femdyn's limit of 200000\n");
  fs::remove(file);
}

TEST_CASE("the nesting limit counts containers, not brackets inside strings", "[hardening]") {
  // 64 levels: the top-level object and 63 arrays.
  const std::string deep = std::string(63, '[') + std::string(63, ']');
  CHECK_THAT(text_error(R"({"name": "x", "description": )" + deep + "}"),
             !Catch::Contains("nested deeper"));
  CHECK_THAT(text_error(R"({"name": ")" + std::string(100, '[') + R"(\\\"", "bodies": []})"),
             !Catch::Contains("nested deeper"));
  CHECK(text_error(R"({"description": )" + deep.substr(0, 63) + "[" + deep.substr(63) + "]}") ==
        "test: JSON nested deeper than 64 levels (femdyn's limit)");
}

TEST_CASE("200,000 bodies with elements load, one more is refused before parsing",
          "[hardening][scale]") {
  const Model chain = load_text(scaling::model_json(200'000, false));
  CHECK(chain.n() == 200'000);
  CHECK(chain.elements.size() == 200'000);
  const Model tree = load_text(scaling::model_json(50'000, true));
  CHECK(tree.n() == 50'000);
  CHECK(text_error(scaling::model_json(200'001, false)) ==
        "test: /bodies: 200001 bodies: more than femdyn's limit of 200000");
}

namespace {

// A URDF serial chain of `links` links (a 1 kg link on each revolute joint but the root).
std::string urdf_chain(int links) {
  std::string s = R"(<robot name="long"><link name="l0"/>)";
  s.reserve(300 * static_cast<std::size_t>(links));
  const auto joint = [&](const std::string& name, int parent, int child) {
    s += R"(<joint name=")" + name + R"(" type="revolute"><parent link="l)" +
         std::to_string(parent) + R"("/><child link="l)" + std::to_string(child) +
         R"("/><origin xyz="0 0 0.01"/><axis xyz="0 1 0"/></joint>)";
  };
  for (int i = 1; i < links; ++i) {
    s += R"(<link name="l)" + std::to_string(i) +
         R"("><inertial><mass value="1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" )"
         R"(ixz="0" iyz="0"/></inertial></link>)";
    joint("j" + std::to_string(i), i - 1, i);
  }
  return s + "</robot>";
}

}  // namespace

TEST_CASE("a 10,000-link URDF is read, its links are checked in one walk", "[hardening][scale]") {
  const UrdfResult r = urdf_to_model(urdf_chain(10'000), "long.urdf");
  CHECK(r.model["bodies"].size() == 9'999);
  CHECK(parse_model_json(r.model, "long.urdf").bodies.size() == 9'999);
  // As a MODEL file: converted, read and compiled.
  const fs::path file = scratch() / "long.urdf";
  std::ofstream(file.string()) << urdf_chain(10'000);
  CHECK(load_model(file.string()).n() == 9'999);
  fs::remove(file);
  // Two links that hang from each other and not from the root: found by the same walk.
  std::string loop = urdf_chain(10'000);
  loop.insert(loop.size() - 8,
              R"(<link name="a"/><link name="b"/>)"
              R"(<joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>)"
              R"(<joint name="ba" type="fixed"><parent link="b"/><child link="a"/></joint>)");
  CHECK_THROWS_WITH(urdf_to_model(loop, "long.urdf"),
                    "long.urdf: link 'a': is on a loop of joints");
  // More links than the body limit: refused by count before the joints are read.
  std::string many = R"(<robot name="many">)";
  for (int i = 0; i < 200'002; ++i) many += R"(<link name="l)" + std::to_string(i) + R"("/>)";
  CHECK_THROWS_WITH(
      urdf_to_model(many + "</robot>", "many.urdf"),
      "many.urdf: 200001 bodies: more than femdyn's limit of 200000 (one per <link> but the root)");
}

TEST_CASE("every command given options but no MODEL says so in one line, exit 2",
          "[hardening][cli]") {
  // `track --csv F` without a MODEL printed a foreign range-check text: each command's options
  // that name files are looked at only once its MODEL is known.
  struct Case {
    const char* command;
    const char* expected;
  };
  for (const Case& c :
       {Case{"track --csv /tmp/femdyn_no_model.csv --to 1", "one MODEL"},
        Case{"simulate --out /tmp/femdyn_no_model.csv", "one MODEL"},
        Case{"view --out /tmp/femdyn_no_model.html", "one MODEL"},
        Case{"import -o /tmp/femdyn_no_model.json", "one MODEL"},
        Case{"linearize --json", "one MODEL"}, Case{"kinematics --q 1", "one MODEL"},
        Case{"equations --json", "one MODEL"}, Case{"check", "one MODEL"},
        Case{"info", "one MODEL"}, Case{"validate", "a MODEL"}, Case{"compare", "two MODEL"},
        Case{"bench", "one MODEL"}}) {
    INFO(c.command);
    const Run r = run(c.command);
    CHECK(r.code == 2);
    CHECK_THAT(r.out, Catch::Contains(c.expected) && Catch::EndsWith("(try --help)\n"));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
  }
}

TEST_CASE("hostile option values on the newer surfaces: one line, exit 2, never NaN or a crash",
          "[hardening]") {
  // Each command of issue 45's surfaces (loops, multi-DOF joints, frames, track, linearize,
  // kinematics, view, a JSON model referring to a URDF) given, option by option, NaN, a huge
  // value, a negative or zero one where it must be positive, the wrong count, an unknown name
  // and a control character.
  Scratch s("hostile_options");
  const std::string urdf_ref = (s.dir / "arm.json").string();
  std::ofstream(urdf_ref) << R"({"model": "urdf", "params": {"file": ")"
                          << model_path("urdf/arm7.urdf") << R"(", "root_joint": "free"}})";
  const std::string loop = model_path("five_bar.json"), space = model_path("space_robot.json"),
                    delta = model_path("delta.json"), out = (s.dir / "o.html").string();
  const std::vector<std::string> cases = {
      "linearize " + loop + " --q nan,0,0,0,0",
      "linearize " + loop + " --qd 1e300,0,0,0,0",
      "linearize " + loop + " --q 0,0",
      "linearize " + loop + " --baumgarte -1",
      "linearize " + urdf_ref + " --tau 1,2,3",
      "linearize " + space + " --q 1e300",
      "kinematics " + delta + " --frame nope",
      "kinematics " + delta + " --frame \x1b[31m",
      "kinematics " + delta + " --axes sideways",
      "kinematics " + urdf_ref + " --qd nan",
      "kinematics " + space + " --max-memory -4",
      "track " + model_path("finger.json") + " --to nan,0,0,0",
      "track " + model_path("finger.json") + " --to 0,0",
      "track " + model_path("finger.json") + " --to 0.1,0,0,0 --duration -1",
      "track " + model_path("finger.json") + " --to 0.1,0,0,0 --steps 0",
      "track " + model_path("finger.json") + " --to 0.1,0,0,0 --kp 1e300 --kd 1",
      "track " + model_path("finger.json") + " --to 0.1,0,0,0 --kp 1 --kd 1 --control sometimes",
      "view " + loop + " --q nan,0,0,0,0 --out " + out,
      "view " + space + " --q 0,0 --out " + out,
      "view " + urdf_ref + " --gravity 0,0,1e300 --out " + out,
      "check " + loop + " --states -3",
      "check " + loop + " --tol nan",
      "check " + space + " --t-end 1e300",
      "check " + space + " --states 0",
      "simulate " + loop + " --t-end 1 --q0 0,nan,0,0,0",
      "simulate " + urdf_ref + " --t-end 1 --qd0 1,2",
  };
  for (const std::string& c : cases) {
    const Run r = run(c);
    INFO(c << "\n" << r.out);
    CHECK(r.code == 2);
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);  // one line
    // NaN only as the user's own text, quoted ('nan'), never as a number femdyn printed
    std::size_t nans = 0, quoted = 0;
    for (std::size_t at = r.out.find("nan"); at != std::string::npos;
         at = r.out.find("nan", at + 1))
      ++nans, quoted += at > 0 && r.out[at - 1] == '\'';
    CHECK(nans == quoted);
    CHECK(r.out.find('\x1b') == std::string::npos);  // a control character shown escaped
  }
}

TEST_CASE("check runs on a floating base, whose q has more entries than q̇", "[hardening]") {
  // Its time probe handed forward dynamics q̇'s size of zeros as q: every floating-base model
  // failed with "tree_forward_dynamics: q has 33 entries; … n_q = 34".
  for (const std::string& model :
       {model_path("space_robot.json"),
        std::string(FEMDYN_SOURCE_DIR) + "/tests/data/mjcf/floating.xml"}) {
    const Run r = run("check " + model + " --states 2 --t-end 0.05");
    INFO(model << "\n" << r.out);
    CHECK(r.code == 0);
    CHECK_THAT(r.out, Catch::Contains("largest stable step"));
  }
}

TEST_CASE("check on loops that cannot close refuses as simulate does, no NaN report",
          "[hardening][loops]") {
  // The five-bar's tips held 10 m apart: they are at most about 1 m apart. check printed
  // "cond from beyond 1.8e308 to 0", rank -1 and "unlimited" steps, and exited 0.
  Scratch dir("check_far_loop");
  json doc = json::parse(read_file(model_path("five_bar.json")));
  doc["constraints"] = json::parse(R"([{"name": "far", "type": "distance", "length": 10,
      "a": {"body": "left_distal", "xyz": [0.3, 0, 0]},
      "b": {"body": "right_distal", "xyz": [0.3, 0, 0]}}])");
  const std::string file = dir / "far.json";
  std::ofstream(file) << doc.dump();
  for (const char* json_flag : {"", " --json"}) {
    const Run r = run("check " + file + json_flag);
    INFO(r.out);
    CHECK(r.code == 1);
    CHECK_THAT(r.out, Catch::StartsWith("femdyn check: " + file +
                                        ": the loops close at none of the 10 states tried: ") &&
                          Catch::Contains("'far'"));
    CHECK(std::count(r.out.begin(), r.out.end(), '\n') == 1);
    // NaN only as the user's own text, quoted ('nan'), never as a number femdyn printed
    std::size_t nans = 0, quoted = 0;
    for (std::size_t at = r.out.find("nan"); at != std::string::npos;
         at = r.out.find("nan", at + 1))
      ++nans, quoted += at > 0 && r.out[at - 1] == '\'';
    CHECK(nans == quoted);
  }
  CHECK(run("simulate " + file + " --t-end 0.1").code == 1);
}

TEST_CASE("with --force too, no output replaces an input of the run", "[hardening]") {
  // The robot file a JSON model refers to, and a run's --tau-csv or --traj, are inputs as much
  // as the model file: each command refuses to write onto them, with --force too (issue 45).
  Scratch dir("force_onto_input");
  const std::string urdf = dir / "robot.urdf", model = dir / "robot.json", tau = dir / "tau.csv",
                    traj = dir / "traj.csv";
  fs::copy_file(model_path("urdf/arm7.urdf"), urdf);
  std::ofstream(model) << R"({"model": "urdf", "params": {"file": "robot.urdf"}})";
  std::ofstream(tau) << "t,theta\n0,0\n0.1,0\n";
  const std::string before = read_file(urdf), tau_before = read_file(tau);
  const std::string pendulum = model_path("pendulum.json");
  REQUIRE(run("simulate " + pendulum + " --t-end 0.01 --out " + traj).code == 0);
  const std::string traj_before = read_file(traj);
  struct Case {
    std::string command, refusal;
  };
  for (const Case& c : {Case{"import " + model + " -o " + urdf + " --force",
                             "-o " + urdf + " is the robot file the model refers to"},
                        Case{"simulate " + model + " --t-end 0.01 --out " + urdf + " --force",
                             "--out " + urdf + " is the robot file the model refers to"},
                        Case{"view " + model + " --out " + urdf + " --force",
                             "--out " + urdf + " is the robot file the model refers to"},
                        Case{"track " + model + " --to 0,0,0,0,0,0,0.1 --csv " + urdf + " --force",
                             "--csv " + urdf + " is the robot file the model refers to"},
                        Case{"simulate " + pendulum + " --tau-csv " + tau + " --t-end 0.01 --out " +
                                 tau + " --force",
                             "--out " + tau + " is the --tau-csv file"},
                        Case{"view " + pendulum + " --traj " + traj + " --out " + traj + " --force",
                             "--out " + traj + " is the --traj file"},
                        Case{"import " + model + " -o " + model + " --force",
                             "-o " + model + " is the model file itself"}}) {
    INFO(c.command);
    const Run r = run(c.command);
    CHECK(r.code == 2);
    CHECK_THAT(r.out, Catch::Contains(c.refusal));
  }
  CHECK(read_file(urdf) == before);
  CHECK(read_file(tau) == tau_before);
  CHECK(read_file(traj) == traj_before);
}
