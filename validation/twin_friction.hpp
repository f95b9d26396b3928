// Coulomb friction for the Simbody twins (twin_mobilizers.cpp, urdf_twin.cpp): Simbody has no
// such force element, so femdyn's regularised law (core/joints/passive.hpp) is a Force::Custom;
// and the flexible bars' damping matrix, another.
// Includes Simbody: only the twins' translation units include it.
#pragma once
#include <Simbody.h>

#include <cmath>
#include <vector>

namespace femdyn::validation {

// Coulomb friction on a one-rate mobility, femdyn's regularised law f = −F_c tanh(u / v_s).
class CoulombFriction : public SimTK::Force::Custom::Implementation {
 public:
  CoulombFriction(const SimTK::MobilizedBody& mobod, double friction, double velocity)
      : mobod_(mobod), friction_(friction), velocity_(velocity) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>&,
                 SimTK::Vector_<SimTK::Vec3>&, SimTK::Vector& mobility) const override {
    const double u = mobod_.getOneU(s, SimTK::MobilizerUIndex(0));
    mobod_.applyOneMobilityForce(s, SimTK::MobilizerUIndex(0),
                                 -friction_ * std::tanh(u / velocity_), mobility);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  SimTK::MobilizedBody mobod_;
  double friction_, velocity_;
};

// The flexible bars' damping matrix on one-rate mobilities: f_a = −Σ_b D_ab u_b
// (TwinModel::rate_damping; `mobod[k]` the mobility of rate k's entries).
class RateDampingForce : public SimTK::Force::Custom::Implementation {
 public:
  struct Entry {
    SimTK::MobilizedBody a, b;
    double d = 0;
  };
  explicit RateDampingForce(std::vector<Entry> entries) : entries_(std::move(entries)) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>&,
                 SimTK::Vector_<SimTK::Vec3>&, SimTK::Vector& mobility) const override {
    for (const Entry& e : entries_)
      e.a.applyOneMobilityForce(s, SimTK::MobilizerUIndex(0),
                                -e.d * e.b.getOneU(s, SimTK::MobilizerUIndex(0)), mobility);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  std::vector<Entry> entries_;
};

}  // namespace femdyn::validation
