// The catalog the JSON loader builds from: element types (name -> factory) and parametric
// model plugins (name -> document). The loader is given one (LoadOptions::catalog, or the
// catalog argument of parse_spec): io/ defines what an entry is and never includes elements/
// or models/. femdyn's own catalog is their two lists (elements/registry.cpp,
// models/plugins.cpp), joined in models/catalog.cpp as default_catalog().
#pragma once
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "compile/spec.hpp"
#include "io/params.hpp"
#include "io/registry.hpp"

namespace femdyn {

// Where element factories put the elements they make (a shorthand may make several).
class ElementSink {
 public:
  ElementSink(std::vector<ElementSpec>& out, std::string where)
      : out_(out), where_(std::move(where)) {}
  void add(std::unique_ptr<Element> element, std::vector<std::string> node_labels) {
    out_.push_back({std::move(element), std::move(node_labels), where_});
  }

 private:
  std::vector<ElementSpec>& out_;
  std::string where_;
};

using ElementFactory = void (*)(const Params& params, ElementSink& sink);

struct ElementType {
  std::string_view name;
  ElementFactory make;
};

// A parametric model: parameters -> a femdyn model document (docs/model-format.md), loaded,
// checked and explained exactly like a hand-written one.
using ModelFactory = Json (*)(const Params& params);

struct ModelPlugin {
  std::string_view name;
  ModelFactory expand;
};

struct Catalog {
  Registry<ElementType> elements;
  Registry<ModelPlugin> plugins;
};

// femdyn's element types and model plugins (defined in models/catalog.cpp).
const Catalog& default_catalog();

}  // namespace femdyn
