// User-input errors found while compiling a mechanism. `where` is the location label supplied
// by the front end (for JSON models "file.json: /bodies/3/joint"); compile appends JSON-pointer
// segments to it ("/origin/xyz") to name a field.
#pragma once
#include <stdexcept>
#include <string>

namespace femdyn {

class ModelError : public std::runtime_error {
 public:
  ModelError(const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what) {}
};

}  // namespace femdyn
