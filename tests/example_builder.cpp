// A mechanism described in C++ without JSON (models/builder.hpp): a two-link arm whose elbow
// carries a rigid body and whose tip a point mass, with the wrist following the elbow. Built
// and run by the test suite (docs/tutorial.md shows this file).
#include <iostream>

#include "core/dynamics/equations.hpp"
#include "models/builder.hpp"

int main() {
  using namespace femdyn;
  MechanismBuilder b("arm");  // messages name "arm (builder): /bodies/1/…"
  b.gravity({0, 0, -9.81});
  JointSpec shoulder;
  shoulder.name = "shoulder";
  shoulder.type = JointType::Revolute;
  shoulder.axis = Vec3::UnitY();
  b.body("upper", "world", shoulder);
  b.space_bar("upper", Vec3(0, 0, 0), Vec3(0.4, 0, 0), 1.2,
              Vec3(0.0004, 0.016, 0.016).asDiagonal().toDenseMatrix());
  JointSpec elbow = shoulder;
  elbow.name = "elbow";
  elbow.xyz = {0.4, 0, 0};
  b.body("fore", "upper", elbow);
  b.rigid_body("fore", 0.8, {0.15, 0, 0}, Vec3(0.0002, 0.006, 0.006).asDiagonal());
  JointSpec wrist = shoulder;
  wrist.name = "wrist";
  wrist.xyz = {0.3, 0, 0};
  b.body("hand", "fore", wrist);
  b.node("hand", "tip", {0.08, 0, 0});
  b.lumped_point("hand", std::string("tip"), 0.3);
  b.coupling("wrist", {{"elbow", 0.5}});  // θ_wrist = 0.5 θ_elbow

  const Model model = b.build();  // compile(): the same checks as for a JSON file
  Workspace ws(model);
  const VecX q = VecX::Constant(model.n(), 0.4), qd = VecX::Constant(model.n(), 1.0);
  evaluate(model, ws, q, qd, VecX::Zero(model.n()));
  std::cout << "coordinates:";
  for (const std::string& c : model.coordinate_names) std::cout << " " << c;
  std::cout << "\nM^s =\n" << ws.Ms << "\nh = " << ws.h.transpose() << "\n";
  return model.n() == 2 && forward_dynamics(model, ws, q, qd, VecX::Zero(2)).ok ? 0 : 1;
}
