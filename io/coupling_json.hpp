// A coupling as the JSON format writes it (docs/model-format.md#couplings): {"joint", "follows",
// "ratio" | "polynomial" | "spline" | "four_bar", …}, read and checked, errors naming its place.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "compile/spec.hpp"
#include "io/params.hpp"

namespace femdyn {

CouplingSpec read_coupling(const Params& p);

// "follows": f with "ratio": k, or "follows": [{"joint": f1, "ratio": k1}, …]: a linear
// coupling's, or a gear constraint's, terms.
std::vector<std::pair<std::string, double>> read_linear_terms(const Params& p);

}  // namespace femdyn
