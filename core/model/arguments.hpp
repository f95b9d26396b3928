// Argument checks at core's public entry points (core/dynamics/equations.hpp, frames, momentum,
// loops, derivatives): a state of the wrong size is the caller's error, named in one line before
// any algorithm reads past its end, as Pinocchio's argument checks do. A configuration q has n_q
// entries (four per quaternion of a spherical or free joint), a rate v or q̈ has n; an actuation
// τ has n, or none at all (no actuation).
#pragma once
#include "core/model/errors.hpp"
#include "core/model/model.hpp"

namespace femdyn {

// What a wrong-sized argument throws: "forward_dynamics: q has 7 entries; the model 'satellite'
// has n_q = 8 configuration coordinates".
class ArgumentError : public Error {
 public:
  using Error::Error;
};

enum class ArgumentKind { Configuration, Rate, Actuation };

[[noreturn]] void throw_wrong_size(const Model& model, const char* function, const char* argument,
                                   Eigen::Index size, ArgumentKind kind);

inline void require_size(const Model& model, const char* function, const char* argument,
                         const VecX& x, ArgumentKind kind) {
  const Eigen::Index expected = kind == ArgumentKind::Configuration ? model.n_q() : model.n();
  if (x.size() == expected || (kind == ArgumentKind::Actuation && x.size() == 0)) [[likely]]
    return;
  throw_wrong_size(model, function, argument, x.size(), kind);
}

// q (n_q), and each rate given (n).
inline void require_state(const Model& model, const char* function, const VecX& q,
                          const VecX* v = nullptr, const char* v_name = "v") {
  require_size(model, function, "q", q, ArgumentKind::Configuration);
  if (v) require_size(model, function, v_name, *v, ArgumentKind::Rate);
}

}  // namespace femdyn
