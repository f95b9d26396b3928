// MechanismBuilder: a mechanism described in code, without JSON — bodies with their joints,
// named nodes and elements, couplings (linear or a law), loads — into the plain MechanismSpec
// (compile/spec.hpp) that compile() turns into a Model. The same model as the JSON file that says
// the same things (tests/test_builder.cpp, python/tests). Each call checks its arguments as the
// JSON loader does and throws ModelError naming the place as a JSON path would:
//   "arm (builder): /bodies/1/elements/0/mass: must be > 0, got -1".
// What compile() checks (unknown parents and joints, cycles, a rod that changes length) is
// reported by compile() with the same paths.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "compile/spec.hpp"
#include "core/model/model.hpp"
#include "io/params.hpp"

namespace femdyn {

struct BarSection;  // elements/space_bar.hpp

// A node of a body: a name from its node table ("tip"; "other_body/tip" for a rod's far end),
// or a position in the body frame.
using NodeDescription = std::variant<std::string, Vec3>;

class MechanismBuilder {
 public:
  explicit MechanismBuilder(std::string name);

  void gravity(const Vec3& g);
  // A body hanging from `parent` ("world" for the ground) by `joint` (its name defaults to the
  // body's; `where` is set here). A fixed joint (JointSpec's default type) with an axis other
  // than the default, limits, a spring or a damper is refused, as in a JSON file: that is a
  // moving joint whose type was left out.
  void body(const std::string& name, const std::string& parent, JointSpec joint);
  // A named node of a body (its frame).
  void node(const std::string& body, const std::string& name, const Vec3& position);

  void lumped_point(const std::string& body, const NodeDescription& node, double mass);
  void rotary_node(const std::string& body, const NodeDescription& node, const Mat3& inertia);
  // Mass m, centre of mass c and inertia about c (body axes): a lumped point and a rotary node
  // at "com" (the JSON rigid_body's default "point_rotary").
  void rigid_body(const std::string& body, double mass, const Vec3& com, const Mat3& inertia);
  // A rigid bar from a to b of mass m and centroidal inertia I_c (the JSON "mass"/"inertia"
  // form of space_bar).
  void space_bar(const std::string& body, const NodeDescription& a, const NodeDescription& b,
                 double mass, const Mat3& inertia);
  // A uniform bar from a to b of this material and section (the JSON "density" form).
  void space_bar(const std::string& body, const NodeDescription& a, const NodeDescription& b,
                 const BarSection& section);
  // A flexible bar in its JSON form ({"name", "parent", "length", "segments", "section", …},
  // docs/model-format.md#flexible-bars): its bodies, as a file would give them.
  void flexible_bar(const Json& bar);
  void rod(const std::string& body, const NodeDescription& a, const NodeDescription& b,
           double mass);

  // θ_joint = Σ ratio_i θ_{follows_i} + offset.
  void coupling(const std::string& joint, const std::vector<std::pair<std::string, double>>& terms,
                double offset = 0);
  // θ_joint = law(θ_{follows_1}, …) (core/model/coupling_function.hpp).
  void coupling(const std::string& joint, const std::vector<std::string>& follows,
                std::shared_ptr<const CouplingFunction> law);
  // A coupling made elsewhere (e.g. read from its JSON form: io parse_coupling); its `where`
  // is set here when empty.
  void coupling(CouplingSpec coupling);
  // Where the next coupling is, for a caller that names it before adding it.
  std::string next_coupling() const;
  // A loop constraint or a two-point spring (compile/spec.hpp: their ends by frame, body or
  // "world", or a point on a body); `where` is set here when empty. The next one's place.
  void constraint(ConstraintSpec constraint);
  void spring(SpringSpec spring);
  std::string next_constraint() const;
  std::string next_spring() const;
  std::size_t constraint_count() const { return spec_.constraints.size(); }
  std::size_t spring_count() const { return spec_.springs.size(); }
  // A named frame on a body (docs/model-format.md#frames).
  void frame(const std::string& name, const std::string& body, const Vec3& xyz,
             const Vec3& rpy = Vec3::Zero());
  // A constant force (world frame) at `point` (body frame) and a torque (world frame).
  void load(const std::string& body, const Vec3& point, const Vec3& force, const Vec3& torque);

  const MechanismSpec& spec() const { return spec_; }
  Model build() const;  // compile(spec())

 private:
  BodySpec& body_named(const std::string& name, const char* what);
  std::string next_element(const BodySpec& b) const;  // "…/bodies/i/elements/k"
  std::pair<Vec3, std::string> resolve(const BodySpec& b, const NodeDescription& node,
                                       const std::string& where) const;
  // A space bar's two ends, resolved, refused where they coincide.
  struct BarEnds {
    Vec3 a;
    std::string a_label;
    Vec3 b;
    std::string b_label;
  };
  BarEnds space_bar_ends(const BodySpec& bs, const NodeDescription& a, const NodeDescription& b,
                         const std::string& where) const;
  MechanismSpec spec_;
  int flexible_bars_ = 0;                                     // (for their paths in messages)
  std::map<std::string, std::map<std::string, Vec3>> nodes_;  // body -> name -> position
};

}  // namespace femdyn
