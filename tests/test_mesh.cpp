// Triangle meshes (io/mesh.hpp): reading STL (binary and ASCII) and OBJ, and the solid a closed
// mesh bounds against closed forms (box, tetrahedron), the sphere its refined polyhedra tend to,
// and relations (moving, turning or turning inside out a mesh moves its solid with it).
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>

#include "core/model/errors.hpp"
#include "io/convex_hull.hpp"
#include "io/mesh.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

std::string mesh_path(const std::string& name) {
  return std::string(FEMDYN_SOURCE_DIR) + "/tests/data/mjcf/meshes/" + name;
}

// A box's eight corners and twelve triangles, wound outward.
TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back((k == 1 || k == 2 || k == 5 || k == 6) ? hi.x() : lo.x(),
                            (k == 2 || k == 3 || k == 6 || k == 7) ? hi.y() : lo.y(),
                            k >= 4 ? hi.z() : lo.z());
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

// A solid box of density ρ: m = ρ abc, I = m/12 diag(b² + c², a² + c², a² + b²).
CentroidalMass box_closed_form(const Vec3& lo, const Vec3& hi, double rho) {
  const Vec3 s = hi - lo;
  const double m = rho * s.prod();
  const Vec3 s2 = s.cwiseProduct(s);
  return {m, (lo + hi) / 2,
          Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y()).asDiagonal() * (m / 12)};
}

void check_equal(const CentroidalMass& a, const CentroidalMass& b, double tol) {
  CHECK(std::abs(a.mass - b.mass) <= tol * b.mass);
  CHECK((a.com - b.com).norm() <= tol * std::max(1.0, b.com.norm()));
  CHECK((a.inertia - b.inertia).norm() <= tol * b.inertia.norm());
}

std::string read_error(const std::string& path) {
  try {
    (void)read_mesh(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(read)";
}

}  // namespace

TEST_CASE("mesh: a box's solid equals the closed form, wherever the box is and however wound",
          "[mesh]") {
  const Vec3 lo(0.05, -0.02, 0.01), hi(0.25, 0.04, 0.05);
  check_equal(solid_mass(box_mesh(lo, hi), 2700), box_closed_form(lo, hi, 2700), 1e-13);
  // Far from the mesh's origin: the same body, moved.
  const Vec3 d(30, -40, 12);
  const CentroidalMass far = solid_mass(box_mesh(lo + d, hi + d), 2700);
  check_equal(far, box_closed_form(lo + d, hi + d, 2700), 1e-9);
  // Inside out (every triangle reversed): the same solid, its volume positive.
  TriangleMesh inside_out = box_mesh(lo, hi);
  for (auto& t : inside_out.triangles) std::swap(t[1], t[2]);
  double V = 0;
  check_equal(solid_mass(inside_out, 2700, &V), box_closed_form(lo, hi, 2700), 1e-13);
  CHECK(V == Approx(0.2 * 0.06 * 0.04).epsilon(1e-13));
}

TEST_CASE("mesh: a non-convex solid (two boxes apart) is the two boxes welded", "[mesh]") {
  TriangleMesh two = box_mesh(Vec3(0, 0, 0), Vec3(1, 0.2, 0.2));
  const TriangleMesh b = box_mesh(Vec3(0, 0, 0.5), Vec3(0.2, 0.2, 1.5));
  const auto offset = static_cast<std::uint32_t>(two.vertices.size());
  two.vertices.insert(two.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto t : b.triangles) two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  check_equal(solid_mass(two, 700),
              welded(box_closed_form(Vec3(0, 0, 0), Vec3(1, 0.2, 0.2), 700),
                     box_closed_form(Vec3(0, 0, 0.5), Vec3(0.2, 0.2, 1.5), 700)),
              1e-13);
}

TEST_CASE("mesh: the files' solids equal their closed forms, in every format", "[mesh]") {
  // bar.stl: binary, its header beginning with "solid" (as many exporters write).
  check_equal(solid_mass(read_mesh(mesh_path("bar.stl")), 1),
              box_closed_form(Vec3(0.05, -0.02, 0.01), Vec3(0.25, 0.04, 0.05), 1), 1e-6);
  // wedge: a tetrahedron, V = |det[b−a c−a d−a]|/6, centre the corners' mean; binary and ASCII.
  const TriangleMesh binary = read_mesh(mesh_path("wedge.stl"));
  const TriangleMesh ascii = read_mesh(mesh_path("wedge_ascii.stl"));
  REQUIRE(binary.triangles.size() == 4);
  double Vb = 0, Va = 0;
  const CentroidalMass wb = solid_mass(binary, 1, &Vb), wa = solid_mass(ascii, 1, &Va);
  CHECK(Va == Approx(0.1 * 0.08 * 0.12 / 6).epsilon(1e-12));
  CHECK((wa.com - Vec3(0.11, 0.10, 0.12) / 4).norm() < 1e-15);
  check_equal(wb, wa, 1e-7);  // float32 in the binary file
  // A scale stretches the solid: V by the scales' product.
  double Vs = 0;
  (void)solid_mass(read_mesh(mesh_path("wedge_ascii.stl"), Vec3(1.5, 0.8, 2)), 1, &Vs);
  CHECK(Vs == Approx(Va * 1.5 * 0.8 * 2).epsilon(1e-12));
  // ball.obj: an icosphere of radius r inscribed in the sphere, 320 faces; its solid lies
  // between the sphere's and the inscribed sphere's of radius r cos(θ) (θ: the widest face's
  // angular radius, below 0.16 rad here), and its centre at the origin.
  double V = 0;
  const CentroidalMass ball = solid_mass(read_mesh(mesh_path("ball.obj")), 1, &V);
  const double r = 0.05, sphere = 4.0 / 3 * std::numbers::pi * r * r * r;
  CHECK(V < sphere);
  CHECK(V > sphere * std::pow(std::cos(0.16), 3));
  CHECK(ball.com.norm() < 1e-9 * r);
  // Its inertia is near 2/5 m r² on every axis, and the same about each (icosahedral symmetry).
  CHECK(ball.inertia(0, 0) == Approx(ball.inertia(1, 1)).epsilon(1e-6));
  CHECK(ball.inertia(0, 0) < 0.4 * ball.mass * r * r);
  CHECK(ball.inertia(0, 0) > 0.4 * ball.mass * r * r * std::pow(std::cos(0.16), 2));
}

TEST_CASE("mesh: a bad mesh file is one line naming the file and the problem", "[mesh][errors]") {
  Scratch scratch("mesh_errors");
  const auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = (scratch.dir / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  };
  const auto refused = [&](const std::string& path, const std::string& expected) {
    const std::string message = read_error(path);
    INFO(message);
    CHECK_THAT(message, Catch::Contains(path) && Catch::Contains(expected));
    CHECK(message.find('\n') == std::string::npos);
  };
  refused(write("a.dae", "<COLLADA/>"), "a mesh femdyn does not read (.dae)");
  refused(write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "line 4: face index 4");
  refused(write("zero.obj", "v 0 0 0\nf 0 1 2\n"), "face index 0");
  refused(write("two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), "a face needs three vertices");
  refused(write("word.obj", "v 0 x 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
          "line 1: a vertex needs three numbers");
  std::string nan_stl(80, ' ');  // one triangle, a vertex coordinate NaN (0x7fc00000)
  nan_stl += std::string("\x01\0\0\0", 4) + std::string(12 + 36 + 2, '\0');
  nan_stl.replace(84 + 12 + 4, 4, std::string("\0\0\xc0\x7f", 4));
  refused(write("nan.stl", nan_stl), "NaN or infinite");
  refused(write("empty.obj", "# nothing\n"), "a mesh with no triangle");
  refused(write("cut.stl", "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"), "truncated");
  // A binary STL whose count claims more triangles than it holds reads as ASCII: no triangle.
  refused(write("short.stl", std::string(80, ' ') + std::string("\x05\0\0\0", 4) + "xyz"),
          "a mesh with no triangle");
  refused((scratch.dir / "missing.stl").string(), "missing.stl");
}

TEST_CASE("mesh: a point cloud's convex hull is the solid it spans, wound outward", "[mesh]") {
  // The regular octahedron |x| + |y| + |z| ≤ a: V = 4a³/3, centre 0, I = m a²/5 · 1 (its second
  // moment ∫x² dV is 2a⁵/15). Its six vertices and points inside it, shuffled, moved far away.
  const double a = 0.3, rho = 500;
  std::vector<Vec3> points;
  for (int k = 0; k < 3; ++k)
    points.push_back(a * Vec3::Unit(k)), points.push_back(-a * Vec3::Unit(k));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-a / 3, a / 3);
  for (int k = 0; k < 40; ++k) points.emplace_back(u(rng), u(rng), u(rng));
  std::shuffle(points.begin(), points.end(), rng);
  const Vec3 far(40, -25, 60);
  for (Vec3& p : points) p += far;
  const TriangleMesh hull = convex_hull(points, "cloud");
  CHECK(hull.vertices.size() == 6);
  CHECK(hull.triangles.size() == 8);
  double signed_volume = 0;  // Σ (a − o)·((b − o) × (c − o)) / 6, positive when wound outward
  for (const auto& t : hull.triangles) {
    const Vec3 p = hull.vertices[t[0]] - far, q = hull.vertices[t[1]] - far,
               r = hull.vertices[t[2]] - far;
    CHECK(p.dot(q.cross(r)) > 0);  // each face, seen from the centre, counter-clockwise outside
    signed_volume += p.dot(q.cross(r)) / 6;
  }
  const double m = rho * 4 * a * a * a / 3;
  CHECK(signed_volume == Approx(4 * a * a * a / 3).epsilon(1e-13));
  check_equal(solid_mass(hull, rho), {m, far, Mat3::Identity() * (m * a * a / 5)}, 1e-9);
  // Nothing to weigh: fewer than four points, or all on one plane.
  const auto refusal = [](const std::vector<Vec3>& p) {
    try {
      (void)convex_hull(p, "cloud");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(a hull)");
  };
  CHECK_THAT(
      refusal({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}),
      Catch::Equals("cloud: its convex hull bounds no volume (3 vertices; a solid needs 4)"));
  std::vector<Vec3> flat;
  for (int k = 0; k < 20; ++k) flat.emplace_back(u(rng), u(rng), 2.0);
  CHECK_THAT(refusal(flat), Catch::Contains("cloud: its convex hull bounds no volume (the vertices "
                                            "are all on one plane or line)"));
  CHECK_THAT(refusal({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, NAN, 0), Vec3(0, 0, 1)}),
             Catch::Contains("cloud: a vertex is NaN or infinite"));
}
