// Element equivalence: one body given as a rigid body, as a space bar with its rotary inertia,
// and as four equimomental points gives the same M^s and h. Conformance over every type.
#include <array>
#include <catch2/catch.hpp>
#include <sstream>

#include "compile/compile.hpp"
#include "core/dynamics/equations.hpp"
#include "core/spatial/inertia.hpp"
#include "elements/lumped_point.hpp"
#include "elements/registry.hpp"
#include "elements/space_bar.hpp"
#include "models/model_files.hpp"
#include "models/plugins.hpp"
#include "tests/helpers.hpp"

using namespace femdyn;
using namespace femdyn::test;

namespace {

// A 3-DOF spatial chain whose middle link is described by `middle_elements` (JSON array).
std::string chain_with(const std::string& middle_elements) {
  return R"({"name": "equivalence", "gravity": [0.3, -1.0, -9.81], "bodies": [
    {"name": "a", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]},
     "elements": [{"type": "rigid_body", "mass": 1.0, "com": [0.2, 0, 0],
                   "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.025}}]},
    {"name": "b", "parent": "a", "joint": {"type": "revolute", "axis": [0, 1, 0.2],
     "origin": {"xyz": [0.4, 0, 0], "rpy": [0.1, 0.2, 0.3]}}, "elements": )" +
         middle_elements + R"(},
    {"name": "c", "parent": "b", "joint": {"type": "revolute", "axis": [1, 0, 0],
     "origin": {"xyz": [0.5, 0.05, 0.02]}},
     "elements": [{"type": "lumped_point", "node": [0.1, 0.02, 0.0], "mass": 0.3}]}]})";
}

// The exact bar from a to b (body frame) as mass, centroid and centroidal inertia.
struct Bar {
  Vec3 a{0.02, 0.01, -0.01}, b{0.47, 0.06, 0.03};
  double rho = 2700, A = 4e-4, Iy = 8e-9, Iz = 3e-8;
  Vec3 y_hint{0, 0.3, 1};
};

std::string v3(const Vec3& v) {
  std::ostringstream o;
  o.precision(17);
  o << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return o.str();
}

std::string num(double x) {
  std::ostringstream o;
  o.precision(17);
  o << x;
  return o.str();
}

std::string m3(const Mat3& I) {
  return "[" + v3(I.row(0).transpose()) + ", " + v3(I.row(1).transpose()) + ", " +
         v3(I.row(2).transpose()) + "]";
}

}  // namespace

TEST_CASE("space bar, rigid body and four equimomental points give the same equations",
          "[elements]") {
  const Bar bar;
  const double l = (bar.b - bar.a).norm(), m = bar.rho * bar.A * l;
  const Mat3 R = SpaceBar::bar_frame(bar.a, bar.b, &bar.y_hint);
  // Exact bar about its centroid, bar frame: ρ l diag(Iy+Iz, Iy + A l²/12, Iz + A l²/12).
  const Vec3 d(bar.rho * l * (bar.Iy + bar.Iz), bar.rho * l * (bar.Iy + bar.A * l * l / 12),
               bar.rho * l * (bar.Iz + bar.A * l * l / 12));
  const Mat3 Ic = R * d.asDiagonal() * R.transpose();
  const Vec3 c = 0.5 * (bar.a + bar.b);
  std::ostringstream sb;
  sb.precision(17);
  sb << "[{\"type\": \"space_bar\", \"nodes\": [" << v3(bar.a) << ", " << v3(bar.b)
     << "], \"density\": " << bar.rho << ", \"area\": " << bar.A << ", \"Iy\": " << bar.Iy
     << ", \"Iz\": " << bar.Iz << ", \"section_y\": " << v3(bar.y_hint) << "}]";
  const std::string by_mass = "[{\"type\": \"space_bar\", \"nodes\": [" + v3(bar.a) + ", " +
                              v3(bar.b) + "], \"mass\": " + num(m) + ", \"inertia\": " + m3(Ic) +
                              "}]";
  const std::string rigid = "[{\"type\": \"rigid_body\", \"mass\": " + num(m) +
                            ", \"com\": " + v3(c) + ", \"inertia\": " + m3(Ic) + "}]";
  const std::string four =
      "[{\"type\": \"rigid_body\", \"equivalent\": \"four_points\", "
      "\"mass\": " +
      num(m) + ", \"com\": " + v3(c) + ", \"inertia\": " + m3(Ic) + "}]";
  const Model ref = load_text(chain_with(sb.str()));
  const Model models[] = {load_text(chain_with(by_mass)), load_text(chain_with(rigid)),
                          load_text(chain_with(four))};
  Workspace wr(ref);
  std::mt19937 rng(5);
  for (int k = 0; k < 5; ++k) {
    const VecX q = random_uniform(3, 3.0, rng), qd = random_uniform(3, 3.0, rng);
    evaluate(ref, wr, q, qd, VecX());
    for (const Model& other : models) {
      Workspace wo(other);
      evaluate(other, wo, q, qd, VecX());
      CHECK(rel_error(wo.Ms, wr.Ms) < 1e-12);
      CHECK(rel_error(wo.h, wr.h) < 1e-12);
      CHECK(rel_error(wo.Q, wr.Q) < 1e-12);
    }
  }
}

TEST_CASE("four equimomental points reproduce the pseudo-inertia", "[elements]") {
  const Vec3 c(0.1, -0.2, 0.05);
  Mat3 I;
  I << 0.02, 0.003, -0.001, 0.003, 0.03, 0.002, -0.001, 0.002, 0.04;
  const auto pts = equimomental_points(2.0, c, I);
  REQUIRE(pts);
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();
  for (const Vec3& p : *pts) {
    Eigen::Vector4d r;
    r << p, 1;
    P += 0.5 * r * r.transpose();
  }
  CHECK((P - pseudo_inertia(2.0, c, I)).cwiseAbs().maxCoeff() < 1e-15);
}

TEST_CASE(
    "every registered element type: symmetric mass, physical total, FD-checked "
    "velocity force",
    "[elements]") {
  // One representative parameter set per type; the conformance checks are type-agnostic.
  const std::map<std::string, std::string> examples = {
      {"lumped_point", R"({"type": "lumped_point", "node": [0.1, 0.2, 0.3], "mass": 0.7})"},
      {"rotary_node", R"({"type": "rotary_node", "node": [0.1, 0, 0],
         "inertia": [[0.02, 0.001, 0], [0.001, 0.03, 0.002], [0, 0.002, 0.04]]})"},
      {"space_bar", R"({"type": "space_bar", "nodes": [[0, 0, 0], [0.3, 0.1, 0]],
         "density": 2700, "area": 1e-4, "Iy": 1e-9, "Iz": 2e-9})"},
      {"rigid_body", R"({"type": "rigid_body", "mass": 1.2, "com": [0.1, 0, 0],
         "inertia": {"ixx": 0.01, "iyy": 0.02, "izz": 0.025, "ixy": 0.001}})"},
      {"rod", R"({"type": "rod", "nodes": [[0, 0, 0], [0.3, 0.1, -0.2]], "mass": 0.5})"}};
  for (const ElementType& t : element_types().entries()) {
    INFO("element type " << t.name);
    REQUIRE(examples.count(std::string(t.name)));
    const Json j = Json::parse(examples.at(std::string(t.name)));
    std::vector<ElementSpec> made;
    ElementSink sink(made, "test");
    t.make(Params(j, "test", "body"), sink);
    REQUIRE(!made.empty());
    MassProperties total;  // accumulated mass
    Mat3 I_origin = Mat3::Zero();
    Vec3 first_moment = Vec3::Zero();
    for (const ElementSpec& es : made) {
      const MatX me = es.element->local_mass();
      CHECK(me.rows() == es.element->local_dof_count());
      CHECK((me - me.transpose()).cwiseAbs().maxCoeff() == 0.0);
      const MassProperties p = es.element->mass_properties();
      total.mass += p.mass;
      first_moment += p.mass * p.com;
      I_origin += p.inertia_origin;
      // Velocity force: bilinear, and g(ω, ω) = ω × (J ω) does no work.
      if (es.element->has_velocity_force()) {
        const int k = es.element->local_dof_count();
        VecX w = VecX::Zero(k), g = VecX::Zero(k);
        for (int node = 0; node < k / 6; ++node) w.segment<3>(6 * node + 3) = Vec3(0.3, -1.1, 0.7);
        es.element->add_velocity_force(w, w, g);
        CHECK(std::abs(w.dot(g)) < 1e-15);
        CHECK(g.norm() > 0);
      }
    }
    // The element's total is a physical body: pseudo-inertia positive semi-definite.
    // (P = [[½ tr(I_o) 1 − I_o, m c], [m cᵀ, m]] with the inertia about the origin.)
    CHECK(total.mass >= 0);
    Eigen::Matrix4d P;
    P.topLeftCorner<3, 3>() = 0.5 * I_origin.trace() * Mat3::Identity() - I_origin;
    P.topRightCorner<3, 1>() = first_moment;
    P.bottomLeftCorner<1, 3>() = first_moment.transpose();
    P(3, 3) = total.mass;
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(P).eigenvalues().minCoeff() >
          -1e-15 * P.norm());
  }
}

TEST_CASE("rotary node: leaving out the gyroscopic term changes h on a 3D chain", "[elements]") {
  // The term lives only where axes are not parallel; check it is really exercised.
  const Model m = load_text(R"({"name": "g", "bodies": [
    {"name": "a", "parent": "world", "joint": {"type": "revolute", "axis": [0, 0, 1]}},
    {"name": "b", "parent": "a", "joint": {"type": "revolute", "axis": [1, 0, 0]},
     "elements": [{"type": "rotary_node", "node": [0, 0, 0],
                   "inertia": {"ixx": 0.03, "iyy": 0.05, "izz": 0.025}}]}]})");
  Workspace ws(m);
  VecX q(2), qd(2);
  q << 0.3, 0.6;
  qd << 1.0, -2.0;
  evaluate(m, ws, q, qd, VecX());
  const VecX h_full = ws.h;
  propagate(m, ws, q, qd, {.jacobian = true, .bias = true});  // forms T
  const VecX without_gyro = ws.T.transpose() * (m.M * ws.bias);
  REQUIRE(without_gyro.size() == 2);
  CHECK((h_full - without_gyro).norm() > 0.1 * h_full.norm());
}

TEST_CASE("the loader builds elements and plugins from the catalog it is given", "[elements][io]") {
  // A catalog with one extra element type, "heavy_point": a lumped point of twice its mass.
  static const std::array types = {ElementType{
      "heavy_point", +[](const Params& p, ElementSink& sink) {
        p.allow_only({"type", "node", "mass"});
        const NodeRef n = p.node("node");
        sink.add(std::make_unique<LumpedPoint>(n.position, 2 * p.positive("mass")), {n.label});
      }}};
  const Catalog custom{Registry<ElementType>(types), model_plugins()};
  const auto pendulum = [](const std::string& element) {
    return R"({"name": "p", "gravity": [0, 0, -9.81], "bodies": [{"name": "bob", "parent":
      "world", "joint": {"type": "revolute", "axis": [0, 1, 0]}, "elements": [)" +
           element + "]}]}";
  };
  const std::string heavy = pendulum(R"({"type": "heavy_point", "node": [0, 0, -1], "mass": 0.5})");
  const Model a = compile(parse_spec(heavy, "custom.json", custom));
  const Model b = load_text(pendulum(R"({"type": "lumped_point", "node": [0, 0, -1], "mass": 1})"));
  Workspace wa(a), wb(b);
  const VecX q = VecX::Constant(1, 0.7), qd = VecX::Constant(1, 1.3);
  evaluate(a, wa, q, qd, VecX());
  evaluate(b, wb, q, qd, VecX());
  CHECK(wa.Ms(0, 0) == Approx(1.0));  // m l² with m = 2 × 0.5
  CHECK(wa.Ms(0, 0) == wb.Ms(0, 0));
  CHECK(wa.Q(0) == wb.Q(0));
  // femdyn's own catalog does not know it, and says which types it knows.
  CHECK_THROWS_WITH(parse_spec(heavy, "custom.json"),
                    "custom.json: /bodies/0/elements/0/type: unknown element type 'heavy_point' "
                    "(known: lumped_point, space_bar, rotary_node, rigid_body, rod)");
  // Nor does the custom one know femdyn's plugins if it is not given them.
  const Catalog no_plugins{Registry<ElementType>(types), Registry<ModelPlugin>({})};
  CHECK_THROWS_WITH(parse_spec(R"({"model": "random_tree"})", "tree.json", no_plugins),
                    Catch::Contains("unknown model plugin 'random_tree' (known: urdf, mjcf)"));
}
