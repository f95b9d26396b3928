#include "core/model/arguments.hpp"

#include <string>

namespace femdyn {

void throw_wrong_size(const Model& model, const char* function, const char* argument,
                      Eigen::Index size, ArgumentKind kind) {
  std::string expected;
  switch (kind) {
    case ArgumentKind::Configuration:
      expected = "n_q = " + std::to_string(model.n_q()) + " configuration coordinates";
      break;
    case ArgumentKind::Rate:
      expected = "n = " + std::to_string(model.n()) + " rates";
      break;
    case ArgumentKind::Actuation:
      expected =
          "n = " + std::to_string(model.n()) + " rates (an actuation τ has n entries, or none)";
      break;
  }
  throw ArgumentError(std::string(function) + ": " + argument + " has " + std::to_string(size) +
                      " entries; the model '" + model.name + "' has " + expected);
}

}  // namespace femdyn
