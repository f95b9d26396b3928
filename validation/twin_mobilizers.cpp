// The twin's mechanism (twin_impl.hpp): each femdyn body on a Simbody mobilized body whose
// mobilizer is its joint, the forces, and the system the constraints then close. Compiled like
// twin.cpp (C++17, without NDEBUG).
#include <Simbody.h>

#include "core/model/names.hpp"
#include "validation/simtk_convert.hpp"
#include "validation/twin_constraints.hpp"
#include "validation/twin_friction.hpp"
#include "validation/twin_impl.hpp"
#include "validation/twin_loops.hpp"

namespace femdyn::validation {

namespace {

SimTK::MassProperties mass_properties(const TwinBody& p) {
  const Mat3& I = p.inertia_origin;  // Simbody wants the inertia about the body origin
  return SimTK::MassProperties(
      p.mass, to_simtk(p.com),
      SimTK::Inertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
}

// The rotation whose x and y axes are the orthonormal x and y (z = x × y).
SimTK::Rotation frame(const Vec3& x, const Vec3& y) {
  Mat3 R;
  R << x.normalized(), y.normalized(), x.normalized().cross(y.normalized());
  return to_simtk(R);
}

}  // namespace

SimbodyTwin::Impl::Impl(TwinModel tm) : model(std::move(tm)), C_rows(model.C) {
  using namespace SimTK;
  const TwinModel& m = model;
  const int nb = static_cast<int>(m.bodies.size());
  mobod.reserve(nb);
  for (int b = 0; b < nb; ++b) {
    const TwinBody& j = m.bodies[b];
    try {
      add_body(j);
    } catch (const std::exception& e) {
      throw femdyn::Error("Simbody refuses body '" + escaped(j.name) + "': " + one_line(e.what()));
    }
  }
  try {
    rods = loops::add_rods(m, mobod);
  } catch (const std::exception& e) {
    throw femdyn::Error("Simbody refuses a rod: " + one_line(e.what()));
  }
  finish_system();
}

void SimbodyTwin::Impl::add_body(const TwinBody& j) {
  using namespace SimTK;
  {
    MobilizedBody& parent =
        j.parent < 0 ? static_cast<MobilizedBody&>(matter.updGround()) : mobod[j.parent];
    const SimTK::Body::Rigid rigid(mass_properties(j));
    const Rotation R_pj = to_simtk(j.R_pj);
    const SimTK::Vec3 p_pj = to_simtk(j.p_pj);
    switch (j.joint) {
      case TwinBody::Joint::Revolute: {
        const Rotation R_a(UnitVec3(to_simtk(j.axis)), ZAxis);  // Pin turns about z
        mobod.push_back(MobilizedBody::Pin(parent, Transform(R_pj * R_a, p_pj), rigid,
                                           Transform(R_a, SimTK::Vec3(0))));
        break;
      }
      case TwinBody::Joint::Prismatic: {
        const Rotation R_a(UnitVec3(to_simtk(j.axis)), XAxis);  // Slider moves along x
        mobod.push_back(MobilizedBody::Slider(parent, Transform(R_pj * R_a, p_pj), rigid,
                                              Transform(R_a, SimTK::Vec3(0))));
        break;
      }
      case TwinBody::Joint::Helical: {
        const Rotation R_a(UnitVec3(to_simtk(j.axis)), ZAxis);  // Screw: about and along z
        mobod.push_back(MobilizedBody::Screw(parent, Transform(R_pj * R_a, p_pj), rigid,
                                             Transform(R_a, SimTK::Vec3(0)),
                                             j.scalars.at("pitch")));
        break;
      }
      case TwinBody::Joint::Universal: {  // about x, then the new y: x -> a₁, y -> a₂
        const Vec3 a2 = (j.axis2 - j.axis2.dot(j.axis) * j.axis).normalized();
        const Rotation R_a = frame(j.axis, a2);
        mobod.push_back(MobilizedBody::Universal(parent, Transform(R_pj * R_a, p_pj), rigid,
                                                 Transform(R_a, SimTK::Vec3(0))));
        break;
      }
      case TwinBody::Joint::Planar: {  // about z, along F's x and y: x, y, z -> e₁, e₂, n
        const Rotation R_a = frame(j.axis2, j.axis.cross(j.axis2));
        mobod.push_back(MobilizedBody::Planar(parent, Transform(R_pj * R_a, p_pj), rigid,
                                              Transform(R_a, SimTK::Vec3(0))));
        break;
      }
      case TwinBody::Joint::Spherical:
        mobod.push_back(MobilizedBody::Ball(parent, Transform(R_pj, p_pj), rigid, Transform()));
        break;
      case TwinBody::Joint::Free:
        mobod.push_back(MobilizedBody::Free(parent, Transform(R_pj, p_pj), rigid, Transform()));
        break;
      case TwinBody::Joint::Fixed:
        mobod.push_back(MobilizedBody::Weld(parent, Transform(R_pj, p_pj), rigid, Transform()));
        break;
    }
    const bool one_rate = j.joint == TwinBody::Joint::Revolute ||
                          j.joint == TwinBody::Joint::Prismatic ||
                          j.joint == TwinBody::Joint::Helical;
    // A spherical or free joint's damper: −c on each u (Ball's ω, Free's ω and v, in F's axes:
    // the same wrench as femdyn's −c on each rate in the body's axes, the damper being isotropic).
    if (j.theta >= 0 && j.damping != 0 &&
        (j.joint == TwinBody::Joint::Spherical || j.joint == TwinBody::Joint::Free))
      for (int u = 0; u < (j.joint == TwinBody::Joint::Free ? 6 : 3); ++u)
        Force::MobilityLinearDamper(forces, mobod.back(), MobilizerUIndex(u), j.damping);
    if (j.theta >= 0 && one_rate) {
      if (j.stiffness != 0)
        Force::MobilityLinearSpring(forces, mobod.back(), MobilizerQIndex(0), j.stiffness, j.rest);
      if (j.damping != 0)
        Force::MobilityLinearDamper(forces, mobod.back(), MobilizerUIndex(0), j.damping);
      if (j.friction != 0)
        Force::Custom(forces,  // (Simbody takes ownership of the implementation)
                      new CoulombFriction(mobod.back(), j.friction, j.friction_velocity));
      if (j.stop)
        Force::MobilityLinearStop(forces, mobod.back(), MobilizerQIndex(0), j.stop_stiffness,
                                  j.stop_dissipation, j.lower, j.upper);
    }
  }
}

void SimbodyTwin::Impl::finish_system() {
  using namespace SimTK;
  const TwinModel& m = model;
  if (m.gravity.norm() > 0)
    Force::Gravity(forces, matter, UnitVec3(to_simtk(m.gravity)), m.gravity.norm());
  for (const TwinModel::Load& l : m.loads) {
    if (!l.force.isZero(0))
      Force::ConstantForce(forces, mobod[l.body], to_simtk(l.point), to_simtk(l.force));
    if (!l.torque.isZero(0)) Force::ConstantTorque(forces, mobod[l.body], to_simtk(l.torque));
  }
  if (!m.rate_damping.empty()) {  // (Simbody takes ownership of the implementation)
    std::vector<RateDampingForce::Entry> entries;
    for (const TwinModel::RateDamping& r : m.rate_damping)
      entries.push_back({mobod[m.theta_body[r.a]], mobod[m.theta_body[r.b]], r.d});
    Force::Custom(forces, new RateDampingForce(std::move(entries)));
  }
  try {
    constraints::add_springs(forces, matter, m, mobod);
  } catch (const std::exception& e) {
    throw femdyn::Error("Simbody refuses a spring: " + one_line(e.what()));
  }
  loop_constraints = constraints::add_constraints(matter, m, mobod);

  if (m.closed_loop()) {  // the laws and rods as constraints, pointwise and for trajectories
    independent = m.coordinate_theta;
    loops::add_constraints(matter, m, mobod, rods);
  } else {
    add_linear_couplers();
  }
  finish_state();
}

}  // namespace femdyn::validation
