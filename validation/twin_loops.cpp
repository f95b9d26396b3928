// The closed loops of the Simbody twin (twin_loops.hpp). Compiled like twin.cpp.
#include "validation/twin_loops.hpp"

#include <stdexcept>
#include <string>

#include "core/model/names.hpp"
#include "validation/simtk_convert.hpp"

namespace femdyn::validation::loops {

namespace {

// φ(θ_t, θ_s1, …, θ_sk) = θ_t − f(θ_s1, …, θ_sk): the coupler's constraint function, with
// ∂φ/∂θ_t = 1, ∂φ/∂θ_si = −f_i, and second derivatives −f_ij (none involve θ_t).
class LawConstraint final : public SimTK::Function {
 public:
  explicit LawConstraint(TwinLaw law)
      : law_(std::move(law)),
        k_(static_cast<int>(law_.sources.size())),
        x_(k_),
        df_(k_),
        d2f_(k_ * k_) {}
  using SimTK::Function::calcDerivative;

  double calcValue(const SimTK::Vector& x) const override { return x[0] - f(x); }

  double calcDerivative(const SimTK::Array_<int>& c, const SimTK::Vector& x) const override {
    f(x);
    if (c.size() == 1) return c[0] == 0 ? 1.0 : -df_[c[0] - 1];
    if (c.size() == 2) return c[0] == 0 || c[1] == 0 ? 0.0 : -d2f_[(c[0] - 1) * k_ + c[1] - 1];
    throw femdyn::Error("coupling law of joint '" + escaped(law_.name) +
                        "': derivatives above the second are not available");
  }
  int getArgumentSize() const override { return 1 + k_; }
  int getMaxDerivativeOrder() const override { return 2; }

 private:
  double f(const SimTK::Vector& x) const {
    for (int i = 0; i < k_; ++i) x_[i] = x[1 + i];
    double value = 0;
    if (!law_.law(x_.data(), value, df_.data(), d2f_.data()))
      throw femdyn::Error("the coupling law of joint '" + escaped(law_.name) +
                          "' is not defined at this posture");
    return value;
  }
  TwinLaw law_;
  int k_;
  mutable std::vector<double> x_, df_, d2f_;
};

}  // namespace

void joint_state(const TwinModel& m, const VecX& q, const VecX& qd, VecX& theta, VecX& theta_dot) {
  theta = VecX::Zero(std::max(m.n_theta_q, m.n_theta()));
  theta_dot = VecX::Zero(m.n_theta());
  int n_q = 0;
  const std::vector<int> first = m.configuration_layout(m.coordinate_theta, n_q);
  for (std::size_t b = 0; b < m.bodies.size(); ++b)  // the coordinates' joints: θ = q
    for (int k = 0; first[b] >= 0 && k < coordinates_of(m.bodies[b].joint); ++k)
      theta[m.bodies[b].theta + k] = q[first[b] + k];
  for (int k = 0; k < m.n(); ++k) theta_dot[m.coordinate_theta[k]] = qd[k];
  std::vector<double> x, df, d2f;
  for (const TwinLaw& law : m.laws) {  // (laws act on joints of one coordinate)
    const std::size_t k = law.sources.size();
    x.resize(k), df.resize(k), d2f.resize(k * k);
    for (std::size_t i = 0; i < k; ++i) x[i] = theta[m.theta_of_rate(law.sources[i])];
    double f = 0;
    if (!law.law(x.data(), f, df.data(), d2f.data()))
      throw femdyn::Error("the coupling law of joint '" + escaped(law.name) +
                          "' is not defined at this state");
    theta[m.theta_of_rate(law.theta)] = f;
    double rate = 0;
    for (std::size_t i = 0; i < k; ++i) rate += df[i] * theta_dot[law.sources[i]];
    theta_dot[law.theta] = rate;
  }
}

std::vector<SimTK::MobilizedBody> add_rods(const TwinModel& m,
                                           std::vector<SimTK::MobilizedBody>& tree) {
  using namespace SimTK;
  std::vector<MobilizedBody> rods;
  for (const TwinRod& r : m.rods) {
    const double L = r.length, mass = r.mass;
    // Inertia about the body origin (the end a): mL²/12 about the centre plus m (L/2)².
    const MassProperties props(mass, SimTK::Vec3(0, 0, L / 2),
                               Inertia(mass * L * L / 3, mass * L * L / 3, 0));
    rods.push_back(MobilizedBody::LineOrientation(tree[r.body_a], Transform(to_simtk(r.point_a)),
                                                  Body::Rigid(props), Transform()));
  }
  return rods;
}

void add_constraints(SimTK::SimbodyMatterSubsystem& matter, const TwinModel& m,
                     std::vector<SimTK::MobilizedBody>& tree,
                     std::vector<SimTK::MobilizedBody>& rods) {
  using namespace SimTK;
  for (std::size_t i = 0; i < m.rods.size(); ++i)
    Constraint::Ball(rods[i], SimTK::Vec3(0, 0, m.rods[i].length), tree[m.rods[i].body_b],
                     to_simtk(m.rods[i].point_b));
  for (const TwinLaw& law : m.laws) {
    bool closed = false;
    for (const TwinRod& r : m.rods) closed |= r.closes == law.theta;
    if (closed) continue;
    std::vector<MobilizedBodyIndex> bodies{tree[m.theta_body[law.theta]].getMobilizedBodyIndex()};
    for (int s : law.sources) bodies.push_back(tree[m.theta_body[s]].getMobilizedBodyIndex());
    const std::vector<MobilizerQIndex> which(bodies.size(), MobilizerQIndex(0));
    auto f = std::make_unique<LawConstraint>(law);
    Constraint::CoordinateCoupler(matter, f.release(), bodies, which);  // Simbody owns f
  }
}

void fit_rods(const SimTK::MultibodySystem& system, SimTK::State& state, const TwinModel& m,
              const std::vector<SimTK::MobilizedBody>& tree,
              const std::vector<SimTK::MobilizedBody>& rods) {
  using namespace SimTK;
  const std::size_t nr = m.rods.size();
  for (std::size_t i = 0; i < nr; ++i) rods[i].setUToFitAngularVelocity(state, SimTK::Vec3(0));
  system.realize(state, Stage::Position);  // the tree's poses (the rods are leaves)
  std::vector<SimTK::Vec3> d_F(nr);
  for (std::size_t i = 0; i < nr; ++i) {
    const TwinRod& r = m.rods[i];
    const SimTK::Vec3 a = tree[r.body_a].findStationLocationInGround(state, to_simtk(r.point_a));
    const SimTK::Vec3 b = tree[r.body_b].findStationLocationInGround(state, to_simtk(r.point_b));
    d_F[i] = ~tree[r.body_a].getBodyRotation(state) * (b - a);
  }
  for (std::size_t i = 0; i < nr; ++i)
    rods[i].setQToFitRotation(state, Rotation(UnitVec3(d_F[i]), ZAxis));
  system.realize(state, Stage::Velocity);
  std::vector<SimTK::Vec3> w_F(nr);
  for (std::size_t i = 0; i < nr; ++i) {
    const TwinRod& r = m.rods[i];
    const MobilizedBody& A = tree[r.body_a];
    const SimTK::Vec3 a = A.findStationLocationInGround(state, to_simtk(r.point_a));
    const SimTK::Vec3 b = tree[r.body_b].findStationLocationInGround(state, to_simtk(r.point_b));
    const SimTK::Vec3 v_rel =
        tree[r.body_b].findStationVelocityInGround(state, to_simtk(r.point_b)) -
        A.findStationVelocityInGround(state, to_simtk(r.point_a)) -
        A.getBodyAngularVelocity(state) % (b - a);
    const SimTK::Vec3 d = (b - a).normalize();
    w_F[i] = ~A.getBodyRotation(state) * (d % v_rel / (b - a).norm());
  }
  for (std::size_t i = 0; i < nr; ++i) rods[i].setUToFitAngularVelocity(state, w_F[i]);
  system.realize(state, Stage::Velocity);
}

}  // namespace femdyn::validation::loops
