// Errors femdyn reports to its user. femdyn::Error is the base of all of them: its constructor
// makes the whole message safe to print (core/model/message.hpp: one line, control characters
// escaped, bounded length), so no message can echo user text raw, whoever formats it.
// ModelError: user-input errors found while reading or compiling a mechanism. `where` is the
// location label supplied by the front end (for JSON models "file.json: /bodies/3/joint");
// compile appends JSON-pointer segments to it ("/origin/xyz") to name a field.
// StateError: the equations cannot be evaluated at a given state (a coupling law undefined there,
// a linkage that cannot assemble; a singular M^s; a q̈ that overflows). Evaluation throws only
// this, never ModelError: a compiled model is valid, a state may not be.
#pragma once
#include <stdexcept>
#include <string>
#include <string_view>

#include "core/model/message.hpp"

namespace femdyn {

class Error : public std::runtime_error {
 public:
  explicit Error(std::string_view text) : std::runtime_error(safe_message(text)) {}
};

class ModelError : public Error {
 public:
  ModelError(const std::string& where, const std::string& what)
      : Error(where.empty() ? what : where + ": " + what) {}
};

class StateError : public Error {
 public:
  using Error::Error;
};

}  // namespace femdyn
