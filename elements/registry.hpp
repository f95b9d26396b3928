// The element registry: element type name -> factory. One explicit list (registry.cpp); adding
// a type is one file pair in elements/ plus one line there — no core file changes.
#pragma once
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "core/spec.hpp"
#include "io/params.hpp"
#include "io/registry.hpp"

namespace femdyn {

// Where factories put the elements they make (a shorthand may make several).
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

const Registry<ElementType>& element_types();

}  // namespace femdyn
