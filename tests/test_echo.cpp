// Echoed user text (issue 22): every error message is one line of printable text whatever the
// input holds (ESC, a line break, DEL, the C1 control U+009B, NUL, bytes that are not UTF-8),
// long echoes are cut with "…", and CSV columns cannot shift (RFC 4180 quoting, read back).
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/model/errors.hpp"
#include "core/model/message.hpp"
#include "core/model/names.hpp"
#include "io/actuation_table.hpp"
#include "io/csv.hpp"
#include "io/output.hpp"
#include "io/trajectory_csv.hpp"
#include "io/urdf_loader.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;
using nlohmann::json;

namespace {

// The four control characters of the issue, and what escaped() makes of them.
const std::pair<std::string, std::string> kControls[] = {
    {"\x1b[31m", "\\x1b[31m"}, {"a\nb", "a\\x0ab"}, {"\x7f", "\\x7f"}, {"\xc2\x9b", "\\xc2\\x9b"}};

// One line, printable: what every message must be.
bool one_printable_line(const std::string& s) { return printable_text(s); }

std::string urdf_error(const std::string& text) {
  try {
    urdf_to_model(text, "r.urdf");
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(loaded)";
}

// models/pendulum.json as JSON, to be mutated.
json echo_pendulum() { return json::parse(read_file(model_path("pendulum.json"))); }

// A two-link arm whose joints are named `a` and `b`.
std::string two_joints(const std::string& a, const std::string& b) {
  const auto body = [](const std::string& name, const std::string& parent, const std::string& j) {
    return json{{"name", name},
                {"parent", parent},
                {"joint", {{"name", j}, {"type", "revolute"}, {"axis", {0, 1, 0}}}},
                {"elements", {{{"type", "lumped_point"}, {"node", {1, 0, 0}}, {"mass", 1}}}}};
  };
  return json{{"name", "two"}, {"bodies", {body("l1", "world", a), body("l2", "l1", b)}}}.dump();
}

std::string urdf_with(const std::string& joint_type, const std::string& parent,
                      const std::string& ixx, const std::string& mimic) {
  return "<robot name='r'><link name='base'/><link name='l1'><inertial><mass value='1'/>"
         "<inertia ixx='" +
         ixx +
         "' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial></link>"
         "<joint name='j1' type='" +
         joint_type + "'><parent link='" + parent + "'/><child link='l1'/><axis xyz='0 0 1'/>" +
         mimic + "</joint></robot>";
}

}  // namespace

TEST_CASE("escaping: idempotent, UTF-8 kept, not-UTF-8 and controls escaped, lengths bounded",
          "[echo]") {
  for (const auto& [raw, shown] : kControls) {
    CHECK(escaped(raw) == shown);
    CHECK(escaped(escaped(raw)) == shown);  // "\x1b" written out stays as it is
    CHECK_FALSE(printable_text(raw));
    CHECK(printable_text(shown));
  }
  CHECK(escaped("θ̇ → q̈ …") == "θ̇ → q̈ …");
  CHECK(escaped(std::string("a\0b", 3)) == "a\\x00b");
  CHECK(escaped("\xff\xc3") == "\\xff\\xc3");  // not UTF-8: a stray byte, a cut sequence
  // Cut at a character boundary: "é" is 2 bytes, never halved.
  const std::string e200(200, 'e');
  CHECK(truncated(e200) == e200);
  CHECK(truncated(e200 + "e") == e200 + "…");
  CHECK(truncated(std::string(199, 'x') + "é") == std::string(199, 'x') + "…");
  CHECK(printable_text(truncated(std::string(199, 'x') + "é")));
  // A whole message keeps its start and its end, bounded, and stays printable.
  const std::string big = "file: /bodies/0/parent: " + std::string(5'000'000, '\x1b') + " end";
  const std::string safe = safe_message(big);
  CHECK(safe.size() < 4 * kMaxMessageBytes + 16);
  CHECK(safe.rfind("file: /bodies/0/parent: ", 0) == 0);
  CHECK(safe.substr(safe.size() - 4) == " end");
  CHECK(printable_text(safe));
  // Every femdyn error escapes its whole text in its constructor.
  CHECK(std::string(ModelError("m.json: /a\nb", "bad \x1b[2J").what()) ==
        "m.json: /a\\x0ab: bad \\x1b[2J");
  CHECK(std::string(Error("x\x7fy").what()) == "x\\x7fy");
}

TEST_CASE("JSON: unknown joint and element types and keys, plugin params: echoed escaped",
          "[echo]") {
  for (const auto& [raw, shown] : kControls) {
    INFO(shown);
    json j = echo_pendulum();
    j["bodies"][0]["joint"]["type"] = "hinge" + raw;
    std::string e = text_error(j.dump());
    CHECK(e == "test: /bodies/0/joint/type: unknown joint type 'hinge" + shown +
                   "' (expected revolute, continuous, prismatic, fixed, helical, screw, universal, "
                   "planar, spherical, ball or free)");
    j = echo_pendulum();
    j["bodies"][0]["elements"][0]["type"] = "point" + raw;
    e = text_error(j.dump());
    CHECK_THAT(e, Catch::Contains("unknown element type 'point" + shown + "'"));
    CHECK(one_printable_line(e));
    // A key: in the message and in the JSON path (a newline here gave two lines).
    j = echo_pendulum();
    j["bodies"][0]["joint"]["sp" + raw] = 1;
    e = text_error(j.dump());
    CHECK(e == "test: /bodies/0/joint/sp" + shown + ": unknown key 'sp" + shown + "'");
    j = echo_pendulum();
    j["k" + raw] = 1;
    CHECK(text_error(j.dump()) == "test: /k" + shown + ": unknown key 'k" + shown + "'");
    // A plugin's params.
    e = text_error(json{{"model", "random_tree"}, {"params", {{"bodies" + raw, 3}}}}.dump());
    CHECK_THAT(e, Catch::Contains("bodies" + shown));
    CHECK(one_printable_line(e));
    e = text_error(json{{"model", "tree" + raw}}.dump());
    CHECK_THAT(e, Catch::Contains("unknown model plugin 'tree" + shown + "'"));
  }
  // nlohmann's excerpt of malformed JSON escapes C0 but not DEL.
  const std::string e = text_error("{\"name\": \x7f\x1b}");
  CHECK_THAT(e, Catch::StartsWith("test: malformed JSON"));
  CHECK(one_printable_line(e));
}

TEST_CASE("a 50 MB unknown parent name is echoed cut to 200 bytes with …", "[echo]") {
  json j = echo_pendulum();
  j["bodies"][0]["parent"] = std::string(50'000'000, 'w');
  const std::string e = text_error(j.dump());
  CHECK(e == "test: /bodies/0/parent: unknown parent body '" + std::string(200, 'w') + "…'");
  // Cut at a character boundary: 'é' (2 bytes) straddling byte 200 is left out whole.
  j["bodies"][0]["parent"] = std::string(199, 'w') + "é" + std::string(1000, 'w');
  CHECK(text_error(j.dump()) ==
        "test: /bodies/0/parent: unknown parent body '" + std::string(199, 'w') + "…'");
}

TEST_CASE("URDF: attribute values (numbers, joint type, parent link, mimic joint) echoed escaped",
          "[echo]") {
  for (const auto& [raw, shown] : kControls) {
    INFO(shown);
    std::string e = urdf_error(urdf_with("revolute", "base", "1" + raw, ""));
    CHECK_THAT(e, Catch::Contains("ixx=\"1" + shown + "\" is not a number"));
    CHECK(one_printable_line(e));
    e = urdf_error(urdf_with("hinge" + raw, "base", "1", ""));
    CHECK(e == "r.urdf: joint 'j1': unknown type 'hinge" + shown + "'");
    e = urdf_error(urdf_with("revolute", "base" + raw, "1", ""));
    CHECK(e == "r.urdf: joint 'j1': parent link 'base" + shown + "' does not exist");
    e = urdf_error(urdf_with("revolute", "base", "1", "<mimic joint='j" + raw + "'/>"));
    CHECK(e == "r.urdf: joint 'j1': mimics unknown joint 'j" + shown + "'");
  }
}

TEST_CASE("tau-csv: header and data cells echoed escaped, a NUL does not cut the message",
          "[echo]") {
  const Model m = load_model(model_path("pendulum.json"));
  const auto table_error = [&](const std::string& text) -> std::string {
    try {
      ActuationTable(text, "tau.csv", m, ActuationTable::from_text);
    } catch (const ModelError& e) {
      return e.what();
    }
    return "(read)";
  };
  for (auto [raw, shown] : kControls) {
    if (raw == "a\nb") raw = "a\rb", shown = "a\\x0db";  // a line break ends the CSV line
    INFO(shown);
    CHECK(table_error("t,theta" + raw + "\n0,0\n") ==
          "tau.csv:1: column 2 'theta" + shown + "' is not a coordinate of single pendulum");
    CHECK(table_error("t,theta\n0,1" + raw + "\n") ==
          "tau.csv:2: column 2: '1" + shown + "' is not a number");
  }
  CHECK(table_error(std::string("t,theta\n0,1\0002\n", 15)) ==
        "tau.csv:2: column 2: '1\\x002' is not a number");
}

TEST_CASE("CSV: a name with a comma or a quote stays one column, read back by both readers",
          "[echo][csv]") {
  CHECK(csv_field("q_a") == "q_a");
  CHECK(csv_field("q_a,b") == "\"q_a,b\"");
  CHECK(csv_field("say \"hi\"") == "\"say \"\"hi\"\"\"");
  CHECK(csv_field(" x") == "\" x\"");
  CHECK(csv_fields("t, \"q_a,b\" ,\"say \"\"hi\"\"\",", "w") ==
        std::vector<std::string>{"t", "q_a,b", "say \"hi\"", ""});
  CHECK_THROWS_WITH(csv_fields("t,\"a,b", "f.csv:1"),
                    "f.csv:1: column 2: a quoted field has no closing \" on its line");
  CHECK_THROWS_WITH(csv_fields("t,\"a\"b", "f.csv:1"),
                    "f.csv:1: column 2: text after the closing \" of a quoted field");

  const Model m = load_text(two_joints("a,b", "say \"hi\""));
  std::ostringstream out;
  write_trajectory_header(out, m);
  Workspace ws(m);
  const VecX y = VecX::LinSpaced(2 * m.n() + 1, 0.1, 0.5);
  write_trajectory_row(out, 0.25, y, Energy{});
  const TrajectoryTable t = read_trajectory_csv(out.str(), "traj.csv");
  CHECK(t.columns == std::vector<std::string>{"t", "q_a,b", "q_say \"hi\"", "qd_a,b",
                                              "qd_say \"hi\"", "kinetic", "potential", "total",
                                              "work"});
  REQUIRE(t.rows.size() == 1);
  CHECK(t.rows[0].size() == t.columns.size());
  CHECK(t.rows[0][1] == y[0]);
  CHECK(t.rows[0][8] == y[4]);

  // --tau-csv reads a quoted header; the names may come in any order.
  const ActuationTable tau("t,\"say \"\"hi\"\"\",\"tau_a,b\"\n0,2,1\n1,4,3\n", "tau.csv", m,
                           ActuationTable::from_text);
  VecX u(2);
  tau(0.5, u);
  CHECK(u[0] == 2);
  CHECK(u[1] == 3);
}

TEST_CASE("CLI: user text in every echo is one escaped line", "[echo][cli]") {
  Scratch s("echo_cli");
  const std::string model = model_path("pendulum.json");
  const auto check = [](const Run& r, int code, const std::string& contains) {
    INFO(r.out);
    CHECK(r.code == code);
    REQUIRE(!r.out.empty());
    CHECK(r.out.back() == '\n');
    CHECK(one_printable_line(r.out.substr(0, r.out.size() - 1)));
    CHECK_THAT(r.out, Catch::Contains(contains));
  };
  // $'…' is not in every sh: printf makes the bytes.
  const std::string esc = "\"$(printf 'x\\033[2Jy')\"", nl = "\"$(printf 'x\\ny')\"",
                    del = "\"$(printf 'x\\177y')\"", c1 = "\"$(printf 'x\\302\\233y')\"";
  check(run(esc), 2, "femdyn x\\x1b[2Jy: unknown command 'x\\x1b[2Jy'");
  check(run("info " + model + " --" + nl), 2, "unknown option --x\\x0ay");
  check(run("info " + del), 1, "x\\x7fy: cannot open file");
  check(run("simulate " + model + " --t-end 1 --integrator " + c1), 2,
        "--integrator: 'x\\xc2\\x9by' is not one of");
  check(run("simulate " + model + " --t-end 1 --tau-csv " + esc), 1,
        "x\\x1b[2Jy: cannot open file");
  std::ofstream(s / "x\ny") << "old";
  check(run_shell("cd " + s.dir.string() + " && " + FEMDYN_BINARY + " simulate " + model +
                  " --t-end 0.1 --out " + nl),
        2, "--out x\\x0ay: exists (use --force to replace it)");
  check(
      run_shell("cd " + s.dir.string() + " && " + FEMDYN_BINARY + " import " + model + " -o " + nl),
      2, "x\\x0ay: exists (use --force to replace it)");
  std::ofstream(s / "tau.csv") << "t,theta\x1b[31m\n0,0\n";
  check(run("simulate " + model + " --t-end 1 --tau-csv " + s / "tau.csv"), 1,
        "column 2 'theta\\x1b[31m' is not a coordinate");
#ifdef FEMDYN_WITH_SIMBODY
  check(run("stress --class " + esc), 2, "--class: no class 'x\\x1b[2Jy'");
#ifdef NDEBUG  // study refuses to time a build with asserts (the sanitizers' build)
  std::ofstream(s / "file") << "";
  check(run("study " + model + " --quick --out " + s / "file" + "/" + del), 2,
        "/x\\x7fy: cannot create the directory");
#endif
#endif
}

TEST_CASE("CLI: simulate --out and track --csv quote a name with a comma", "[echo][cli][csv]") {
  Scratch s("echo_csv");
  std::ofstream(s / "m.json") << two_joints("a,b", "c");
  Run r = run("simulate " + s / "m.json" + " --t-end 0.01 --integrator rk4 --dt 0.005 --out " +
              s / "t.csv");
  REQUIRE(r.code == 0);
  std::ifstream in(s / "t.csv");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  const TrajectoryTable t = read_trajectory_csv(text, "t.csv");
  CHECK(t.columns[1] == "q_a,b");
  CHECK(t.columns.size() == 9);
  CHECK(t.rows.size() == 3);
  r = run("track " + s / "m.json" + " --to 0.1,0.2 --duration 0.1 --steps 10 --csv " +
          s / "track.csv");
  REQUIRE(r.code == 0);
  std::ifstream tr(s / "track.csv");
  std::string header;
  std::getline(tr, header);
  CHECK(csv_fields(header, "track.csv") == std::vector<std::string>{"t", "q_ref_a,b", "q_ref_c",
                                                                    "tau_a,b", "tau_c", "q_sim_a,b",
                                                                    "q_sim_c"});
}

TEST_CASE(
    "the JSON of --json: DEL and C1 as u-escapes (backslash u), invalid UTF-8 as U+FFFD, and it "
    "parses back",
    "[echo]") {
  const nlohmann::json doc{{"path", std::string("a\x7f") + "b\xc2\x9b" + "c\xff" + "d\x1b"},
                           {"n", 3}};
  const std::string text = json_text(doc);
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    CHECK((c >= 0x20 || c == '\n'));  // the indentation's line breaks only
    CHECK(c != 0x7f);
  }
  CHECK(text.find("\xc2\x9b") == std::string::npos);
  const nlohmann::json back = nlohmann::json::parse(text);
  CHECK(back["path"] ==
        "a\x7f"
        "b\xc2\x9b"
        "c\xef\xbf\xbd"
        "d\x1b");  // U+FFFD for the bad byte
  CHECK(back["n"] == 3);
}
