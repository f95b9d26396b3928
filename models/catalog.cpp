// femdyn's own catalog for the loader (io/catalog.hpp): every element type and model plugin.
#include "elements/registry.hpp"
#include "models/model_files.hpp"
#include "models/plugins.hpp"

namespace femdyn {

const Catalog& default_catalog() {
  static const Catalog catalog{element_types(), model_plugins()};
  return catalog;
}

}  // namespace femdyn
