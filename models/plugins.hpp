// Parametric model plugins: a registered factory from parameters to a mechanism, written as a
// femdyn model document (the plain JSON format of docs/model-format.md), so that a plugin's
// output is loaded, checked and explained exactly like a hand-written model:
//   {"model": "dexterous_finger", "params": {…}}   in a model file.
// One explicit list (plugins.cpp); the loader reaches it through its catalog (io/catalog.hpp).
#pragma once
#include "io/catalog.hpp"

namespace femdyn {

const Registry<ModelPlugin>& model_plugins();

}  // namespace femdyn
