#include "models/plugins.hpp"

#include <array>

#include "models/dexterous_finger.hpp"
#include "models/hand.hpp"
#include "models/random_tree.hpp"
#include "models/space_robot.hpp"

namespace femdyn {

// The one place model plugins are registered.
static const std::array kPlugins = {
    // the paper's 4-joint finger of space bars (lumping exact or the paper's)
    ModelPlugin{"dexterous_finger", &dexterous_finger},
    // a palm on a 2-DOF wrist with four fingers and a thumb
    ModelPlugin{"dexterous_hand", &dexterous_hand},
    // a seeded random tree or chain of rigid bodies (tests, studies, benchmarks)
    ModelPlugin{"random_tree", &random_tree},
    // a free-floating satellite with a 7-DOF arm and the dexterous hand (zero gravity)
    ModelPlugin{"space_robot", &space_robot},
};

const Registry<ModelPlugin>& model_plugins() {
  static const Registry<ModelPlugin> registry{kPlugins};
  return registry;
}

}  // namespace femdyn
