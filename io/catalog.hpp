// The catalog the JSON loader builds from: element types (name -> factory) and parametric
// model plugins (name -> document). The loader is given one: every loading function of
// io/model_loader.hpp takes it as an argument. io/ defines what an entry is and never includes
// or calls elements/ or models/. femdyn's own catalog is their two lists (elements/registry.cpp,
// models/plugins.cpp), joined in models/catalog.cpp as default_catalog() (models/model_files.hpp).
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

}  // namespace femdyn
