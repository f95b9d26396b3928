// Parametric model plugins: a registered factory from parameters to a mechanism, written as a
// femdyn model document (the plain JSON format of docs/model-format.md), so that a plugin's
// output is loaded, checked and explained exactly like a hand-written model.
//   {"model": "dexterous_finger", "params": {…}}   in a model file, or
//   expand_model("dexterous_finger", params)        from C++.
#pragma once
#include <span>
#include <string_view>

#include "io/params.hpp"
#include "io/registry.hpp"

namespace femdyn {

using ModelFactory = Json (*)(const Params& params);

struct ModelPlugin {
  std::string_view name;
  ModelFactory expand;
};

const Registry<ModelPlugin>& model_plugins();

}  // namespace femdyn
