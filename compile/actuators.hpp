// A joint's actuator, friction and stop (JointSpec -> Joint, checked), and what the model
// derives from them once (core/model/model.hpp: the rotors' M_a, the effort limits on q).
#pragma once
#include <string>

#include "compile/spec.hpp"
#include "core/model/model.hpp"

namespace femdyn {

// Checks js's armature, gear, friction, effort and velocity limits and stop, and copies them into
// j (its nv known). Each refusal names js.where and the field.
void compile_actuator(const JointSpec& js, Joint& j);

// After the coordinates are laid out: M_a = Cᵀ diag(I_a G²) C, the effort limit of each rate
// of q (that of the joint owning it; a coupled joint's limit is not applied) and the actuated
// rates of q.
void compile_actuators(Model& m);
// Model::prescribed from the joints' "prescribed": each a joint of one rate that is a coordinate
// of its own (not one that follows a coupling), named in messages by its spec's path.
void compile_prescribed(const MechanismSpec& spec, const std::vector<int>& body_of_spec, Model& m);

// Every free joint of m taken as actuated (as "actuated": true on it: thrusters push the base),
// and m's actuated rates derived again (`femdyn track --actuated-base`).
void actuate_free_joints(Model& m);

}  // namespace femdyn
