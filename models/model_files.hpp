// femdyn's element types and model plugins (models/catalog.cpp), and the model-file functions of
// io/model_loader.hpp with them: what the commands, the Python module, validation and the tests
// call. io takes the catalog as an argument, so io does not reach up into models/.
#pragma once
#include <string>

#include "io/model_loader.hpp"

namespace femdyn {

const Catalog& default_catalog();

inline MechanismSpec read_spec(const std::string& path, const LoadOptions& options = {}) {
  return read_spec(default_catalog(), path, options);
}
inline Model load_model(const std::string& path, const LoadOptions& options = {}) {
  return load_model(default_catalog(), path, options);
}
inline Json model_document(const std::string& path, const LoadOptions& options = {}) {
  return model_document(default_catalog(), path, options);
}
inline MechanismSpec parse_spec(const std::string& text, const std::string& source_name) {
  return parse_spec(text, source_name, default_catalog());
}
inline MechanismSpec parse_model_json(const Json& root, const std::string& source_name) {
  return parse_model_json(root, source_name, default_catalog());
}

}  // namespace femdyn
