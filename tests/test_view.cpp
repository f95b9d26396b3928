// femdyn view, its C++ side (view/): the scene holds the model's bodies, elements and poses as
// the kinematics give them; the page is whole and its scene readable; the command refuses bad
// trajectories in one line, never replaces a file without --force and never leaves half a
// file. The page in a browser: tests/view_browser.py.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/dynamics/body_inertia.hpp"
#include "core/kinematics/frames.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/workspace/workspace.hpp"
#include "io/mesh.hpp"
#include "io/mjcf_loader.hpp"
#include "io/urdf_loader.hpp"
#include "tests/helpers.hpp"
#include "view/page.hpp"
#include "view/scene.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A trajectory CSV as femdyn simulate writes it, made by the command.
std::string simulated(const Scratch& dir, const std::string& model, const std::string& options) {
  const std::string out = dir / "traj.csv";
  const Run r = run("simulate " + model_path(model) + " " + options + " --out " + out);
  REQUIRE(r.code == 0);
  return out;
}

// The scene a page holds, read back from its <script type="application/json">.
nlohmann::json scene_of_page(const std::string& page) {
  const std::string open = "<script type=\"application/json\" id=\"femdyn-scene\">";
  const std::size_t from = page.find(open);
  REQUIRE(from != std::string::npos);
  const std::size_t start = from + open.size(), end = page.find("</script>", start);
  REQUIRE(end != std::string::npos);
  return nlohmann::json::parse(page.substr(start, end - start));
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// The one line of a failed command: non-zero exit, a single line naming `file` and `problem`.
void check_one_line_error(const Run& r, const std::string& file, const std::string& problem) {
  CHECK(r.code != 0);
  CHECK(count_of(r.out, "\n") == 1);
  CHECK(r.out.find(file) != std::string::npos);
  CHECK(r.out.find(problem) != std::string::npos);
}

}  // namespace

TEST_CASE("view: each body's pose per frame is the kinematics' at that frame's q", "[view]") {
  Scratch dir("view_poses");
  const Model m = load_model(model_path("hand.json"));
  const view::Motion motion =
      view::read_trajectory(m, simulated(dir, "hand.json", "--t-end 0.2 --every 20"));
  REQUIRE(motion.frames.size() > 2);
  const nlohmann::json scene = view::scene_json(m, motion, {}, "hand.json");
  CHECK(scene["counts"]["bodies"] == m.bodies.size());
  CHECK(scene["counts"]["elements"] == m.elements.size());
  CHECK(scene["counts"]["frames"] == m.frames.size() - m.bodies.size());
  CHECK(scene["counts"]["motion_frames"] == motion.frames.size());
  Workspace ws(m);
  FrameKinematics k;
  for (std::size_t f = 0; f < motion.frames.size(); f += motion.frames.size() - 1) {
    const VecX& q = motion.frames[f].q;
    const auto& poses = scene["motion"]["poses"][f];
    REQUIRE(poses.size() == 7 * m.bodies.size());
    for (std::size_t b = 0; b < m.bodies.size(); ++b) {
      frame_kinematics(m, ws, q, VecX::Zero(m.n()), static_cast<int>(b),
                       FrameAxes::LocalWorldAligned, k);
      for (int i = 0; i < 3; ++i) CHECK(std::abs(poses[7 * b + i].get<double>() - k.p[i]) < 2e-6);
      const Eigen::Quaterniond page(poses[7 * b + 6].get<double>(), poses[7 * b + 3].get<double>(),
                                    poses[7 * b + 4].get<double>(), poses[7 * b + 5].get<double>());
      CHECK((page.toRotationMatrix() - k.R).cwiseAbs().maxCoeff() < 1e-5);
    }
  }
  // The energy balance comes from the trajectory's columns: E − W stays at E(0).
  const auto& E = scene["motion"]["energy"];
  CHECK(E["source"] == "trajectory");
  const std::size_t last = motion.frames.size() - 1;
  const double drift = E["kinetic"][last].get<double>() + E["potential"][last].get<double>() -
                       E["work"][last].get<double>() - E["kinetic"][0].get<double>() -
                       E["potential"][0].get<double>();
  CHECK(std::abs(drift) < 1e-3 * (1 + std::abs(E["potential"][0].get<double>())));
}

TEST_CASE("view: every bundled model and URDF robot has a page of its posture", "[view]") {
  std::vector<std::string> paths;
  for (const std::string& name : bundled_models()) paths.push_back(model_path(name));
  for (const char* robot : {"urdf/arm7.urdf", "urdf/hand16.urdf", "urdf/gantry.urdf"})
    paths.push_back(model_path(robot));
  for (const char* robot : {"iiwa.urdf", "hyq.urdf", "atlas.urdf"})
    paths.push_back(std::string(FEMDYN_SOURCE_DIR) + "/tests/robots/" + robot);
  for (const std::string& path : paths) {
    INFO(path);
    const Model m = load_model(path);
    const std::string page = view::page_html(view::scene_json(
        m, view::posture(m, neutral_posture(m)),
        is_urdf_path(path) ? urdf_visuals(read_file(path), path) : std::vector<Visual>{}, path));
    const nlohmann::json scene = scene_of_page(page);
    CHECK(scene["bodies"].size() == m.bodies.size());
    CHECK(scene["elements"].size() == m.elements.size());
    CHECK(scene["motion"]["poses"][0].size() == 7 * m.bodies.size());
  }
}

TEST_CASE("view: the page is whole, offline, and holds the scene it was given", "[view]") {
  const Model m = load_model(model_path("finger.json"));
  const nlohmann::json scene =
      view::scene_json(m, view::posture(m, neutral_posture(m)), {}, "finger.json");
  const std::string page = view::page_html(scene);
  CHECK(page.find("<!--femdyn:") == std::string::npos);  // every placeholder filled
  CHECK(page.find("OrbitControls") != std::string::npos);
  for (const char* fetch : {"<script src", "src=\"http", "href=\"http", "<link ", "@import"})
    CHECK(page.find(fetch) == std::string::npos);  // nothing to fetch
  CHECK(scene_of_page(page) == scene);
  // No name can end a script early: 4 scripts, 4 ends, whatever the model is called.
  nlohmann::json named = scene;
  named["model"] = "</script><script>alert(1)</script><!--";
  const std::string hostile = view::page_html(named);
  CHECK(count_of(hostile, "</script>") == 4);
  CHECK(scene_of_page(hostile)["model"] == named["model"]);
}

TEST_CASE("view: a long trajectory keeps at most kMaxFrames, its first and last rows", "[view]") {
  const Model m = load_model(model_path("pendulum.json"));
  TrajectoryTable table;
  table.columns = {"t"};
  for (const std::string& c : m.configuration_names) table.columns.push_back("q_" + c);
  const std::size_t rows = 4 * view::kMaxFrames + 3;
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<double> row(table.columns.size(), std::sin(0.001 * r));
    row[0] = 0.001 * r;
    table.rows.push_back(row);
  }
  const view::Motion motion = view::trajectory(m, table, "long.csv");
  CHECK(motion.frames.size() == view::kMaxFrames);
  CHECK(motion.frames.front().t == 0);
  CHECK(motion.frames.back().t == Approx(0.001 * (rows - 1)));
  CHECK(motion.energy_source == "computed");  // no energy columns: femdyn computes them
}

TEST_CASE("view: a page holds at most a million body poses, the frames thinned evenly",
          "[view][hardening]") {
  // 10,000 bodies × 1,500 frames (15 M poses) took 2.7 GB and aborted with bad_alloc: a model of
  // many bodies keeps fewer frames, kMaxPoses / bodies, the first and last rows among them.
  CHECK(view::frame_limit(1) == view::kMaxFrames);
  CHECK(view::frame_limit(10'000) == 100);
  CHECK(view::frame_limit(100'000'000) == 2);
  Scratch dir("view_thinned");
  const std::string model = (dir.dir / "tree.json").string(),
                    traj = (dir.dir / "traj.csv").string();
  std::ofstream(model) << R"({"model": "random_tree", "params": {"seed": 3, "bodies": 2000}})";
  const Model m = load_model(model);
  std::ofstream csv(traj);
  csv << "t";
  for (const std::string& c : m.configuration_names) csv << ",q_" << c;
  csv << "\n";
  for (int r = 0; r < 1500; ++r) {
    csv << 0.001 * r;
    for (int i = 0; i < m.n_q(); ++i) csv << "," << (i % 7 == 0 ? 0.001 * r : 0.0);
    csv << "\n";
  }
  csv.close();
  const view::Motion motion = view::read_trajectory(m, traj);
  CHECK(motion.rows == 1500);
  REQUIRE(motion.frames.size() == 500);
  CHECK(motion.frames.front().t == 0);
  CHECK(motion.frames.back().t == Approx(1.499));
  const Run r =
      run("view " + model + " --traj " + traj + " --out " + (dir.dir / "page.html").string());
  CHECK(r.code == 0);
  CHECK_THAT(r.out, Catch::Contains("500 frames of the trajectory's 1500 rows, evenly spaced"));
}

TEST_CASE("view: a URDF's visual primitives and their colours are read", "[view]") {
  const std::string path = model_path("urdf/arm7.urdf");
  const std::string text = read_file(path);
  const std::vector<Visual> visuals = urdf_visuals(text, path);
  CHECK(visuals.size() == count_of(text, "<visual>"));
  std::set<std::string> shapes;
  for (const Visual& v : visuals) {
    shapes.insert(v.shape);
    CHECK(v.rgba.has_value());  // inline, or by the robot's material of that name
  }
  CHECK(shapes == std::set<std::string>{"box", "cylinder", "sphere"});
  const std::string bad = R"(<robot name="r"><link name="a"><visual><geometry>
      <cylinder radius="x" length="1"/></geometry></visual></link></robot>)";
  const std::vector<Visual> unread = urdf_visuals(bad, "bad.urdf");  // listed, never fatal
  REQUIRE(unread.size() == 1);
  CHECK(unread[0].shape == "invalid");
  CHECK_THAT(unread[0].mesh_issue, Catch::Contains("bad.urdf") && Catch::Contains("link 'a'"));
}

TEST_CASE("femdyn view writes the page once, replaces it only with --force", "[view][cli]") {
  Scratch dir("view_cli");
  const std::string out = dir / "finger.html";
  const Run first = run("view " + model_path("finger.json") + " --out " + out);
  REQUIRE(first.code == 0);
  const std::string page = read_file(out);
  const nlohmann::json scene = scene_of_page(page);
  const Model m = load_model(model_path("finger.json"));
  CHECK(scene["counts"]["bodies"] == m.bodies.size());
  CHECK(scene["counts"]["elements"] == m.elements.size());

  std::ofstream(out) << "mine";
  const Run again = run("view " + model_path("finger.json") + " --out " + out);
  check_one_line_error(again, out, "exists (use --force");
  CHECK(read_file(out) == "mine");
  CHECK(run("view " + model_path("finger.json") + " --out " + out + " --force").code == 0);
  CHECK(read_file(out).size() == page.size());
  CHECK(dir.files() == 1);  // no temporary file left beside it
}

TEST_CASE("femdyn view refuses a bad trajectory in one line and writes nothing", "[view][cli]") {
  Scratch dir("view_bad");
  const std::string finger = model_path("finger.json"), out = dir / "page.html";
  const std::string traj = simulated(dir, "finger.json", "--t-end 0.01 --every 5");
  std::vector<std::string> lines;
  {
    std::istringstream in(read_file(traj));
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  REQUIRE(lines.size() > 2);
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  std::string header = lines[0], renamed = header;
  renamed.replace(renamed.find(",q_"), 3, ",x_");  // the first coordinate's column renamed
  std::string nan_row = lines[2];                  // its first coordinate NaN
  const std::size_t q0 = nan_row.find(',') + 1;
  nan_row.replace(q0, nan_row.find(',', q0) - q0, "nan");
  const std::string missing = write("missing.csv", renamed + "\n" + lines[1] + "\n");
  const std::string backwards =
      write("back.csv", header + "\n" + lines[2] + "\n" + lines[1] + "\n");
  const std::string empty = write("empty.csv", header + "\n");
  const std::string nan = write("nan.csv", header + "\n" + lines[1] + "\n" + nan_row + "\n");
  const std::string text =
      write("text.csv", header + "\n" + lines[1].substr(0, 2) + "x" + lines[1].substr(2) + "\n");
  check_one_line_error(run("view " + finger + " --traj " + missing + " --out " + out),
                       "missing.csv", "no column 'q_");
  check_one_line_error(run("view " + finger + " --traj " + backwards + " --out " + out), "back.csv",
                       "t goes back");
  check_one_line_error(run("view " + finger + " --traj " + empty + " --out " + out), "empty.csv",
                       "no rows");
  check_one_line_error(run("view " + finger + " --traj " + nan + " --out " + out), "nan.csv: row 2",
                       "is NaN or Inf");
  check_one_line_error(run("view " + finger + " --traj " + text + " --out " + out), "text.csv",
                       "is not a number");
  check_one_line_error(run("view " + finger + " --traj " + (dir / "none.csv") + " --out " + out),
                       "none.csv", "cannot open");
  check_one_line_error(run("view " + finger + " --traj " + traj + " --q 0,0,0,0 --out " + out),
                       "view", "--traj and --q");
  check_one_line_error(run("view " + finger + " --q 0,nan,0,0 --out " + out), "--q", "NaN");
  check_one_line_error(run("view " + finger + " --out " + finger + " --force"), "--out",
                       "is the model file itself");
  CHECK(!std::filesystem::exists(out));
}

namespace {

std::string data_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/tests/data/" + name;
}

// The bytes of a base64 text (RFC 4648), to read back a mesh the scene embeds.
std::vector<unsigned char> from_base64(const std::string& text) {
  const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::vector<unsigned char> out;
  unsigned bits = 0, n = 0;
  for (const char c : text) {
    if (c == '=') break;
    bits = (bits << 6) | static_cast<unsigned>(digits.find(c));
    if ((n += 6) >= 8) out.push_back(static_cast<unsigned char>((bits >> (n -= 8)) & 255));
  }
  return out;
}

}  // namespace

TEST_CASE("view: an MJCF's geoms are drawn, its meshes embedded as the files hold them",
          "[view][mjcf][mesh]") {
  const std::string path = data_path("mjcf/meshes.xml");
  const Model m = load_model(path);
  const MjcfResult read = read_mjcf(path);
  const nlohmann::json scene =
      view::scene_json(m, view::posture(m, neutral_posture(m)), read.visuals, "meshes.xml");
  CHECK(scene["visuals"].size() == 7);      // every geom of groups 0-2
  REQUIRE(scene["not_drawn"].size() == 2);  // the two inline meshes (faces, and vertices alone)
  for (const auto& n : scene["not_drawn"])
    CHECK(n["why"] == "an inline mesh, which the page does not draw");
  REQUIRE(scene["meshes"].size() == 3);
  // The ball: its positions are the OBJ's vertices as float32, its indices the triangles.
  const TriangleMesh ball = read_mesh(data_path("mjcf/meshes/ball.obj"));
  bool found = false;
  for (const auto& mesh : scene["meshes"]) {
    if (mesh["triangles"] != ball.triangles.size()) continue;
    found = true;
    const std::vector<unsigned char> xyz = from_base64(mesh["positions"]);
    const std::vector<unsigned char> idx = from_base64(mesh["indices"]);
    REQUIRE(xyz.size() == ball.vertices.size() * 3 * sizeof(float));
    REQUIRE(idx.size() == ball.triangles.size() * 3 * sizeof(std::uint32_t));
    std::vector<float> p(xyz.size() / sizeof(float));
    std::memcpy(p.data(), xyz.data(), xyz.size());
    double worst = 0;
    for (std::size_t v = 0; v < ball.vertices.size(); ++v)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(p[3 * v + k] - ball.vertices[v][k]));
    CHECK(worst < 1e-8);
    std::uint32_t last = 0;
    std::memcpy(&last, idx.data() + idx.size() - 4, 4);
    CHECK(last == ball.triangles.back()[2]);
  }
  CHECK(found);
  // A geom sits where the body's frame puts it: the upper arm's wedge at its pos, turned by
  // its euler (radians), in the frame of the femdyn body that carries the MuJoCo body.
  for (const auto& v : scene["visuals"])
    if (v["link"] == "upper") {
      CHECK(v["body"] == 1);
      CHECK(std::abs(v["p"][0].get<double>() - 0.02) < 1e-6);
      CHECK(std::abs(v["p"][1].get<double>() - 0.01) < 1e-6);
    }
}

TEST_CASE(
    "view: a URDF's meshes are found (relative, package://, Collada) and placed on "
    "their link's body",
    "[view][mesh]") {
  const std::string path = data_path("urdf/meshed/meshed_arm.urdf");
  const Model m = load_model(path);
  const std::vector<Visual> visuals = urdf_visuals(read_file(path), path);
  REQUIRE(visuals.size() == 6);
  for (const Visual& v : visuals)
    if (v.shape == "mesh") CHECK(!v.mesh_path.empty());  // every file found
  const nlohmann::json scene =
      view::scene_json(m, view::posture(m, neutral_posture(m)), visuals, "meshed_arm.urdf");
  CHECK(scene["not_drawn"].empty());
  CHECK(scene["meshes"].size() == 4);  // bar, wedge ×(2 2 1), ball, the Collada camera
  std::size_t collada = 0;
  for (const auto& mesh : scene["meshes"]) collada += mesh.contains("collada");
  CHECK(collada == 1);
  CHECK(scene["counts"]["visuals"] == 6);
  // Each visual's bounding sphere about its origin frames the camera: a mesh's is its farthest
  // vertex (scaled), a primitive's from its sizes.
  for (std::size_t k = 0; k < visuals.size(); ++k) {
    const Visual& v = visuals[k];
    const auto& shown = scene["visuals"][k];
    if (v.shape == "box") CHECK(shown["radius"] == Approx(0.5 * v.size.norm()).margin(1e-6));
    if (v.shape == "mesh" && !shown.contains("radius")) continue;  // (Collada: the page's)
    if (v.shape == "mesh" && !scene["meshes"][shown["mesh"].get<int>()].contains("collada")) {
      const TriangleMesh mesh = read_mesh(v.mesh_path, v.size);
      double r = 0;
      for (const Vec3& p : mesh.vertices) r = std::max(r, p.norm());
      CHECK(shown["radius"] == Approx(r).margin(1e-6));
      CHECK(r > 0);
    }
  }
  // The root link is welded to the world: its visual is drawn on the world (-1).
  CHECK(scene["visuals"][0]["link"] == "base");
  CHECK(scene["visuals"][0]["body"] == -1);
  // A missing mesh is listed with why, and the page still written.
  std::vector<Visual> missing = visuals;
  missing[0].mesh_path.clear();
  missing[0].mesh_issue = "not found";
  const nlohmann::json partial =
      view::scene_json(m, view::posture(m, neutral_posture(m)), missing, "meshed_arm.urdf");
  REQUIRE(partial["not_drawn"].size() == 1);
  CHECK(partial["not_drawn"][0]["why"] == "not found");
}

// A body without visuals is drawn as its inertia box: the box of the same mass whose principal
// moments are the body's, m (b² + c²)/12 = I₁ and so on. A loop constraint's two places are in
// the scene, on their bodies.
TEST_CASE("view: inertia boxes hold each body's moments, and loop closures are in the scene",
          "[view][loops]") {
  const Model m = load_model(model_path("five_bar.json"));
  const nlohmann::json scene =
      view::scene_json(m, view::posture(m, neutral_posture(m)), {}, "five_bar.json");
  const std::vector<MassProperties> mp = body_mass_properties(m);
  std::size_t massive = 0;
  for (const MassProperties& p : mp) massive += p.mass > 0;
  REQUIRE(scene["inertia_boxes"].size() == massive);
  for (const auto& box : scene["inertia_boxes"]) {
    const MassProperties& p = mp[box["body"].get<std::size_t>()];
    const Vec3 e(box["size"][0], box["size"][1], box["size"][2]);
    const Vec3 moments =
        Vec3(e[1] * e[1] + e[2] * e[2], e[0] * e[0] + e[2] * e[2], e[0] * e[0] + e[1] * e[1]) *
        (p.mass / 12);
    const Eigen::SelfAdjointEigenSolver<Mat3> principal(p.inertia_com());
    CHECK((moments - principal.eigenvalues()).norm() < 1e-5 * principal.eigenvalues().norm());
  }
  REQUIRE(scene["constraints"].size() == m.constraints.size());
  CHECK(scene["constraints"][0]["a"]["body"] == m.constraints[0].a.body);
  CHECK(scene["constraints"][0]["b"]["body"] == m.constraints[0].b.body);
}

// A flexible bar is drawn along its centreline: the scene names its stations, clamp to tip,
// whose origins lie on the straight bar at rest at Δ/2 steps of Δ (the parts' joints, the middle
// of each part) and at its ends, and its radius, the tube's √(J/A) = √((R² + r²)/2); its pieces
// get no inertia box. Bent, the stations follow the bend: each lies at the posture's kinematics.
TEST_CASE("view: a flexible bar's centreline and radius are in the scene", "[view][flexible]") {
  const Model m = load_model(model_path("flexible_space_robot.json"));
  const nlohmann::json scene = view::scene_json(m, view::posture(m, neutral_posture(m)), {}, "");
  REQUIRE(scene["bars"].size() == 2);
  REQUIRE(scene["counts"]["bars"] == 2);
  const double R = 0.05, r = 0.047, L = 3, delta = L / 8;  // docs/flexible.md: 6061-T6 tubes
  std::set<int> pieces;
  for (const nlohmann::json& bar : scene["bars"]) {
    CHECK(bar["radius"].get<double>() == Approx(std::sqrt((R * R + r * r) / 2)).epsilon(2e-3));
    const std::vector<int> stations = bar["stations"];
    REQUIRE(stations.size() == 10);  // the clamp, 8 joints, the tip
    pieces.insert(stations.begin(), stations.end());
    const auto origin = [&](int k) {
      const nlohmann::json& p = scene["motion"]["poses"][0];
      return Vec3(p[7 * stations[k]], p[7 * stations[k] + 1], p[7 * stations[k] + 2]);
    };
    const Vec3 axis = (origin(9) - origin(0)).normalized();
    CHECK((origin(9) - origin(0)).norm() == Approx(L).epsilon(1e-6));
    for (int k = 1; k < 10; ++k) {
      const double step = (origin(k) - origin(k - 1)).norm();
      CHECK(step == Approx(k == 1 || k == 9 ? delta / 2 : delta).epsilon(1e-6));
      CHECK((origin(k) - origin(k - 1)).cross(axis).norm() < 1e-6);
    }
  }
  for (const nlohmann::json& box : scene["inertia_boxes"])
    CHECK(pieces.count(box["body"].get<int>()) == 0);
  // Bent: every station where the kinematics put its body.
  VecX q = neutral_posture(m);
  for (int i = 0; i < m.n_q(); ++i)
    if (m.configuration_names[i].find(".rz") != std::string::npos) q[i] = 0.1;
  const nlohmann::json bent = view::scene_json(m, view::posture(m, q), {}, "");
  Workspace ws(m);
  propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = false, .bias = false, .rows = false});
  for (const nlohmann::json& bar : bent["bars"])
    for (int s : bar["stations"]) {
      const nlohmann::json& p = bent["motion"]["poses"][0];
      CHECK((Vec3(p[7 * s], p[7 * s + 1], p[7 * s + 2]) - (ws.origin + ws.body[s].p)).norm() <
            2e-6);
    }
}

// A visual the page cannot draw never stops the view: it is listed with its link and why; a
// mesh's negative scale (a mirror image, as humanoids' left and right limbs share one file) is
// drawn.
TEST_CASE("view: a bad visual is listed as not drawn, a mirrored mesh is drawn", "[view][mesh]") {
  Scratch dir("view_bad_visual");
  const std::string path = dir / "arm.urdf";
  std::ofstream(path) << "<robot name='arm'><link name='base'/><link name='arm'><inertial><mass "
                         "value='1'/><inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/>"
                         "</inertial><visual><geometry><box size='0.1 -0.2 0.1'/></geometry>"
                         "</visual><visual><geometry><mesh filename='"
                      << data_path("mjcf/meshes/bar.stl")
                      << "' scale='-1 1 1'/></geometry></visual></link><joint name='j' "
                         "type='continuous'><parent link='base'/><child link='arm'/></joint>"
                         "</robot>";
  const Model m = load_model(path);
  const nlohmann::json scene = view::scene_json(m, view::posture(m, neutral_posture(m)),
                                                urdf_visuals(read_file(path), path), "arm.urdf");
  REQUIRE(scene["not_drawn"].size() == 1);
  CHECK(scene["not_drawn"][0]["link"] == "arm");
  CHECK_THAT(scene["not_drawn"][0]["why"].get<std::string>(), Catch::Contains("a negative size"));
  CHECK(scene["meshes"].size() == 1);
  CHECK(scene["counts"]["visuals"] == 1);
}

TEST_CASE("view: a JSON file that refers to a URDF or MJCF draws that file's visuals",
          "[view][cli][one-truth]") {
  // The same robot through another door looks the same: the page of {"model": "urdf" | "mjcf",
  // "params": {"file"}} holds the visuals, meshes and their bodies that the robot file's page
  // holds (the file named relative to the JSON file, a free root on the URDF).
  Scratch dir("view_reference");
  struct Case {
    std::string robot, reference;
  };
  const std::string urdf = data_path("urdf/meshed/meshed_arm.urdf");
  const std::string mjcf = data_path("mjcf/meshes.xml");
  for (const Case& c :
       {Case{urdf, R"({"model": "urdf", "params": {"file": "FILE"}})"},
        Case{mjcf, R"({"model": "mjcf", "params": {"file": "FILE"}, "gravity": [0, 0, -1]})"}}) {
    const std::filesystem::path robot(c.robot);
    std::string text = c.reference;
    const std::string relative =
        std::filesystem::relative(robot, std::filesystem::path(dir.dir)).string();
    text.replace(text.find("FILE"), 4, relative);
    const std::string json = dir / "robot.json";
    std::ofstream(json) << text;
    INFO(text);
    REQUIRE(run("view " + c.robot + " --out " + dir / "robot.html --force").code == 0);
    REQUIRE(run("view " + json + " --out " + dir / "json.html --force").code == 0);
    const nlohmann::json direct = scene_of_page(read_file(dir / "robot.html")),
                         referred = scene_of_page(read_file(dir / "json.html"));
    CHECK(referred["counts"]["visuals"] == direct["counts"]["visuals"]);
    CHECK(direct["counts"]["visuals"] > 0);
    CHECK(referred["visuals"] == direct["visuals"]);
    CHECK(referred["meshes"] == direct["meshes"]);
    CHECK(referred["not_drawn"] == direct["not_drawn"]);
  }
}
