#include "io/mjcf_geometry.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "core/model/names.hpp"

namespace femdyn::mjcf {

namespace {

using Quat = Eigen::Quaterniond;

// The shortest turn taking ẑ to the unit vector z (about x by π for −ẑ), as MuJoCo's compiler.
Quat z_to(const Vec3& z) {
  Vec3 axis = Vec3::UnitZ().cross(z);
  const double s = axis.norm();
  axis = s < 1e-10 ? Vec3(Vec3::UnitX()) : Vec3(axis / s);
  return Quat(Eigen::AngleAxisd(std::atan2(s, z.z()), axis));
}

Vec3 unit(const Document& doc, const XMLElement& e, const char* what, const Vec3& v) {
  if (!(v.norm() > 1e-14)) doc.fail(e, std::string(what) + " is zero");
  return v.normalized();
}

Quat euler_turns(const std::string& seq, const std::vector<double>& angles) {
  Quat q = Quat::Identity();
  for (int i = 0; i < 3; ++i) {
    const char c = seq[static_cast<std::size_t>(i)];
    const Vec3 axis = Vec3::Unit(std::tolower(c) - 'x');
    const Quat r(Eigen::AngleAxisd(angles[static_cast<std::size_t>(i)], axis));
    q = std::islower(c) ? Quat(q * r) : Quat(r * q);  // moving axes post-, fixed pre-multiply
  }
  return q;
}

}  // namespace

Pose pose_of(const Document& doc, const XMLElement& e, const std::string& cls) {
  Pose pose;
  pose.p = doc.vec3(e, "pos", cls, Vec3::Zero());
  const double to_rad = doc.compiler().degrees ? std::numbers::pi / 180 : 1.0;
  int given = 0;
  Quat q = Quat::Identity();
  if (const std::vector<double> w = doc.numbers(e, "quat", cls, 4); !w.empty()) {
    ++given;
    const Eigen::Vector4d v(w[0], w[1], w[2], w[3]);
    if (!(v.norm() > 1e-14)) doc.fail(e, "quat is zero");
    q = Quat(w[0], w[1], w[2], w[3]).normalized();
  }
  if (const std::vector<double> a = doc.numbers(e, "axisangle", cls, 4); !a.empty()) {
    ++given;
    q = Quat(
        Eigen::AngleAxisd(a[3] * to_rad, unit(doc, e, "axisangle's axis", {a[0], a[1], a[2]})));
  }
  if (std::vector<double> a = doc.numbers(e, "euler", cls, 3); !a.empty()) {
    ++given;
    for (double& x : a) x *= to_rad;
    q = euler_turns(doc.compiler().eulerseq, a);
  }
  if (const std::vector<double> a = doc.numbers(e, "xyaxes", cls, 6); !a.empty()) {
    ++given;
    const Vec3 x = unit(doc, e, "xyaxes' x", {a[0], a[1], a[2]});
    Vec3 y(a[3], a[4], a[5]);
    y = unit(doc, e, "xyaxes' y, made normal to x,", y - x * x.dot(y));
    Mat3 R;
    R << x, y, x.cross(y);
    q = Quat(R).normalized();
  }
  if (const std::vector<double> a = doc.numbers(e, "zaxis", cls, 3); !a.empty()) {
    ++given;
    q = z_to(unit(doc, e, "zaxis", {a[0], a[1], a[2]}));
  }
  if (given > 1) doc.fail(e, "more than one orientation (quat, axisangle, euler, xyaxes, zaxis)");
  pose.R = q.toRotationMatrix();
  return pose;
}

GeomShape geom_shape(const Document& doc, const XMLElement& geom, const std::string& cls) {
  const char* type_c = doc.attr(geom, "type", cls);
  GeomShape g;
  g.type = type_c ? type_c : "sphere";
  const std::vector<double> size = doc.numbers(geom, "size", cls, -1);
  const auto need = [&](std::size_t n) {
    if (size.size() < n)
      doc.fail(geom, "a " + g.type + " needs " + std::to_string(n) + " size number" +
                         (n == 1 ? "" : "s"));
    for (std::size_t k = 0; k < n; ++k)
      if (!(size[k] > 0)) doc.fail(geom, "size: a " + g.type + "'s sizes must be positive");
  };
  g.pose = pose_of(doc, geom, cls);
  if (const std::vector<double> ft = doc.numbers(geom, "fromto", cls, 6); !ft.empty()) {
    if (g.type != "capsule" && g.type != "cylinder")
      doc.fail(geom, "fromto on a " + g.type + " (femdyn reads it on a capsule or a cylinder)");
    const Vec3 a(ft[0], ft[1], ft[2]), b(ft[3], ft[4], ft[5]);
    if (!((b - a).norm() > 0)) doc.fail(geom, "fromto: its two points coincide");
    g.pose.p = (a + b) / 2;
    g.pose.R = z_to((b - a).normalized()).toRotationMatrix();
    need(1);
    g.size = Vec3(size[0], (b - a).norm() / 2, 0);
  } else if (g.type == "capsule" || g.type == "cylinder") {
    need(2);
    g.size = Vec3(size[0], size[1], 0);
  } else if (g.type == "sphere") {
    need(1);
    g.size = Vec3(size[0], 0, 0);
  } else if (g.type == "box" || g.type == "ellipsoid") {
    need(3);
    g.size = Vec3(size[0], size[1], size[2]);
  }
  return g;
}

GeomMass primitive_geom_mass(const Document& doc, const XMLElement& geom, const std::string& cls) {
  const GeomShape shape = geom_shape(doc, geom, cls);
  const std::string& type = shape.type;
  const Vec3& size = shape.size;
  GeomMass g;
  g.pose = shape.pose;
  const double r = size[0], h = size[1];
  constexpr double pi = std::numbers::pi;
  double V = 0;
  Vec3 k = Vec3::Zero();  // I = m k, per axis
  if (type == "sphere") {
    V = 4.0 / 3 * pi * std::pow(size[0], 3);
    k.setConstant(0.4 * size[0] * size[0]);
  } else if (type == "box" || type == "ellipsoid") {
    const Vec3 s2(size[0] * size[0], size[1] * size[1], size[2] * size[2]);
    const double f = type == "box" ? 1.0 / 3 : 1.0 / 5;
    V = type == "box" ? 8 * size[0] * size[1] * size[2]
                      : 4.0 / 3 * pi * size[0] * size[1] * size[2];
    k = f * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  } else if (type == "cylinder") {
    V = 2 * pi * r * r * h;
    k = Vec3((3 * r * r + 4 * h * h) / 12, (3 * r * r + 4 * h * h) / 12, r * r / 2);
  } else if (type == "capsule") {
    const double Vs = 4.0 / 3 * pi * r * r * r, Vc = 2 * pi * r * r * h;
    V = Vs + Vc;
    const double fs = Vs / V, fc = Vc / V;  // mass fractions
    const double perp =
        fc * (3 * r * r + 4 * h * h) / 12 + fs * (0.4 * r * r + h * h + 0.75 * h * r);
    k = Vec3(perp, perp, fc * r * r / 2 + fs * 0.4 * r * r);
  } else {
    doc.fail(geom, "type " + quoted_text(type) + " has no volume femdyn computes");
  }
  const std::vector<double> given = doc.numbers(geom, "mass", cls, 1);
  if (!given.empty()) {
    g.mass = given[0];
  } else {
    g.mass = doc.number(geom, "density", cls, 1000) * V;
  }
  if (g.mass < 0) doc.fail(geom, "a negative mass or density");
  g.I = (g.mass * k).asDiagonal();
  return g;
}

}  // namespace femdyn::mjcf
