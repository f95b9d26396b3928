// femdyn as a library: load a model, evaluate M^s, h, Q at a state, forward and inverse
// dynamics. Built and run by the test suite (docs/tutorial.md shows this file).
#include <iostream>

#include "core/dynamics/equations.hpp"
#include "models/model_files.hpp"

int main(int argc, char** argv) {
  using namespace femdyn;
  const std::string path = argc > 1 ? argv[1] : "models/finger.json";
  const Model model = load_model(path);  // throws ModelError("file: /json/path: problem")
  Workspace ws(model);                   // all buffers, sized once: no allocation per call

  VecX q = VecX::Constant(model.n(), 0.3), qd = VecX::Constant(model.n(), 1.0);
  VecX tau = VecX::Zero(model.n());
  evaluate(model, ws, q, qd, tau);                            // ws.Ms, ws.h, ws.Q
  const Status st = forward_dynamics(model, ws, q, qd, tau);  // ws.qdd
  if (!st.ok) {
    std::cerr << path << ": " << st.message << "\n";
    return 1;
  }
  std::cout << "M^s =\n"
            << ws.Ms << "\nh = " << ws.h.transpose() << "\nQ = " << ws.Q.transpose()
            << "\nqdd = " << ws.qdd.transpose() << "\n";

  // Inverse dynamics of that acceleration gives back the actuation (zero).
  const VecX qdd = ws.qdd;
  inverse_dynamics(model, ws, q, qd, qdd);
  const double residual = ws.tau.cwiseAbs().maxCoeff();
  std::cout << "inverse dynamics residual = " << residual << "\n";
  return residual < 1e-9 * (1 + ws.Q.cwiseAbs().maxCoeff()) ? 0 : 1;
}
