// Frames (Model::frames): named places on bodies, and their kinematics for control — pose,
// Jacobian, velocity and J̇v — in three sets of axes (docs/notation.md#frames).
//
// A frame F on body B at (R_BF, p_BF), with r = R_B p_BF:
//   R_F = R_B R_BF,   p_F = p_B + r,   ω_F = ω_B,   v_F = v_B + ω_B × r       (world axes)
//   J = [Jv_B − [r]× Jω_B ; Jω_B]                           (6 × n, linear rows first)
//   J̇v (q̈ = 0): a_F = a_B + α_B × r + ω_B × (ω_B × r),  α_F = α_B           (classical)
// In each set of axes J v is that form's velocity and J̇v = (d/dt J) v its derivative at q̈ = 0,
// so that the form's acceleration is J q̈ + J̇v:
//   LocalWorldAligned  (v_F, ω) in world axes;          J̇v = (a_F, α_F)
//   Local              Rᵀ(v_F, ω) in the frame's axes;  J̇v = (Rᵀa_F − ω_l × v_l, Rᵀα_F)
//   World              (v_F + p_F × ω, ω): the motion of the body point at the world origin,
//                      world axes (spatial velocity); J̇v = (a_F + v_F × ω + p_F × α_F, α_F)
#pragma once
#include <string>

#include "core/model/attachment.hpp"
#include "core/spatial/spatial.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {

enum class FrameAxes { LocalWorldAligned, Local, World };

struct FrameKinematics {
  Mat3 R = Mat3::Identity();     // R_WF
  Vec3 p = Vec3::Zero();         // p_WF
  MatX J;                        // 6 × n: linear rows, then angular
  Vec6 velocity = Vec6::Zero();  // J v
  Vec6 bias = Vec6::Zero();      // J̇v
};

// The index of the frame named `name` in Model::frames, or -1.
int find_frame(const Model& model, const std::string& name);

// The kinematics of frame `frame` in `axes` from the body states and Jacobians of the last
// propagate(model, ws, q, v, {.jacobian = true, .bias = true}) — one propagate serves every frame.
void frame_kinematics(const Model& model, const Workspace& ws, int frame, FrameAxes axes,
                      FrameKinematics& out);
// The same at (q, v), after its own propagate.
void frame_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v, int frame,
                      FrameAxes axes, FrameKinematics& out);

// The motion of an attachment A (a body point with axes, core/model/attachment.hpp), world axes,
// from the last propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false}); with
// r = R_b p:
//   p_A = p_b + r,   R_A = R_b R,   v_A = v_b + ω_b × r,   ω_A = ω_b,
//   J_A = [Jv_b − [r]× Jω_b ; Jω_b],   bias (q̈ = 0): a_A = a_b + α_b × r + ω_b × (ω_b × r), α_A =
//   α_b.
void attachment_motion(const Model& model, const Workspace& ws, const Attachment& A,
                       AttachmentMotion& out, bool jacobian = true);

// "local_world_aligned", "local", "world" (and back; false if the text names none).
const char* frame_axes_name(FrameAxes axes);
bool parse_frame_axes(const std::string& text, FrameAxes& axes);

}  // namespace femdyn
