// The generated cases of femdyn stress (docs/stability.md): each a model description (femdyn
// JSON) and a scenario. Grouped by class; --quick keeps a subset of each class.
#pragma once
#include <string>
#include <vector>

#include "io/params.hpp"

namespace femdyn::cli {

struct StressCase {
  std::string klass, name, description;
  Json model;                   // femdyn JSON document
  std::vector<double> q0, qd0;  // empty: zero
  double t_end = 1, dt = 1e-3;
  bool large = false;
  std::string expect;  // the verdict's first word the tests hold it to
};

std::vector<StressCase> stress_cases(bool quick);

}  // namespace femdyn::cli
