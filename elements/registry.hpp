// The element registry: element type name -> factory. One explicit list (registry.cpp); adding
// a type is one file pair in elements/ plus one line there — no core or io file changes. The
// loader reaches it through the catalog it is given (io/catalog.hpp).
#pragma once
#include "io/catalog.hpp"

namespace femdyn {

const Registry<ElementType>& element_types();

}  // namespace femdyn
