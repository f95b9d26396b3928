#include "models/plugins.hpp"

#include <array>

#include "models/dexterous_finger.hpp"
#include "models/hand.hpp"
#include "models/random_tree.hpp"

namespace femdyn {

// The one place model plugins are registered.
static const std::array kPlugins = {
    ModelPlugin{"dexterous_finger", &dexterous_finger,
                "the paper's 4-joint finger of space bars (lumping exact or the paper's)"},
    ModelPlugin{"dexterous_hand", &dexterous_hand,
                "a palm on a 2-DOF wrist with four fingers and a thumb"},
    ModelPlugin{"random_tree", &random_tree,
                "a seeded random tree or chain of rigid bodies (tests, studies, benchmarks)"},
};

std::span<const ModelPlugin> model_plugins() { return kPlugins; }

const ModelPlugin* find_model_plugin(std::string_view name) {
  for (const ModelPlugin& p : kPlugins)
    if (p.name == name) return &p;
  return nullptr;
}

}  // namespace femdyn
