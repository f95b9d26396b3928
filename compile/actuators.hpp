// A joint's actuator, friction and stop (JointSpec -> Joint, checked), and what the model
// derives from them once (core/model.hpp: the rotors' M_a, the effort limits on q).
#pragma once
#include <string>

#include "compile/spec.hpp"
#include "core/model.hpp"

namespace femdyn {

// Checks js's armature, gear, friction, effort and velocity limits and stop, and copies them into
// j (its nv known). Each refusal names js.where and the field.
void compile_actuator(const JointSpec& js, Joint& j);

// After the coordinates are laid out: M_a = Cᵀ diag(I_a G²) C and the effort limit of each rate
// of q (that of the joint owning it; a coupled joint's limit is not applied).
void compile_actuators(Model& m);

}  // namespace femdyn
