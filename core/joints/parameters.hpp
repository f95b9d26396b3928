// What a joint type reads of its description besides its origin and the motion every moving
// joint may have (limits, spring, damper, actuator): its axes and its own numbers. Each type
// declares them (core/joints/<type>.hpp: `axes`, and `scalars` if it has any), and every reader
// asks the type through joint_parameters (core/joints/kernel.hpp): the JSON loader, compile, the
// C++ and Python builders. A parameter is declared once, by the type that reads it.
#pragma once
#include <span>
#include <string_view>

#include "core/model/model.hpp"

namespace femdyn {

// The axes a type reads: none (fixed, spherical, free), `axis`, or `axis` and `axis2`.
enum class JointAxes { None, One, Two };

// A number a type reads (helical's pitch): its key in model files and builders, where compile
// stores it in the Joint, what it means (for messages and docs), and a value the tests build the
// type with.
struct JointScalar {
  std::string_view key;
  double Joint::*value;
  std::string_view meaning;
  double example;
};

struct JointParameters {
  JointAxes axes = JointAxes::None;
  std::span<const JointScalar> scalars;
  bool moves = true;  // a fixed joint has no motion: no limits, spring, damper or actuator
};

}  // namespace femdyn
