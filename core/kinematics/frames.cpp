#include "core/kinematics/frames.hpp"

#include "core/kinematics/kinematics.hpp"
#include "core/model/arguments.hpp"

namespace femdyn {

int find_frame(const Model& model, const std::string& name) {
  for (std::size_t f = 0; f < model.frames.size(); ++f)
    if (model.frames[f].name == name) return static_cast<int>(f);
  return -1;
}

void frame_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v, int frame,
                      FrameAxes axes, FrameKinematics& out) {
  require_state(model, "frame_kinematics", q, &v);
  propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
  frame_kinematics(model, ws, frame, axes, out);
}

void frame_kinematics(const Model& model, const Workspace& ws, int frame, FrameAxes axes,
                      FrameKinematics& out) {
  const Frame& F = model.frames.at(frame);
  const BodyState& B = ws.body[F.body];
  const Vec3 r = B.R * F.p_BF;
  out.R = B.R * F.R_BF;
  out.p = ws.origin + (B.p + r);
  const auto Jw = ws.Jw.middleRows<3>(3 * F.body), Jv = ws.Jv.middleRows<3>(3 * F.body);
  out.J.resize(6, model.n());
  out.J.topRows<3>() = Jv;
  out.J.topRows<3>().noalias() -= skew(r) * Jw;
  out.J.bottomRows<3>() = Jw;
  const Vec3 w = B.w, vF = B.v + w.cross(r);
  const Vec3 alpha = B.alpha, aF = B.a + alpha.cross(r) + w.cross(w.cross(r));
  switch (axes) {
    case FrameAxes::LocalWorldAligned:
      out.velocity << vF, w;
      out.bias << aF, alpha;
      break;
    case FrameAxes::Local: {
      const Mat3 Rt = out.R.transpose();
      out.J.topRows<3>() = Rt * out.J.topRows<3>();
      out.J.bottomRows<3>() = Rt * out.J.bottomRows<3>();
      const Vec3 vl = Rt * vF, wl = Rt * w;
      out.velocity << vl, wl;
      out.bias << Rt * aF - wl.cross(vl), Rt * alpha;
      break;
    }
    case FrameAxes::World:
      out.J.topRows<3>().noalias() += skew(out.p) * out.J.bottomRows<3>();
      out.velocity << vF + out.p.cross(w), w;
      out.bias << aF + vF.cross(w) + out.p.cross(alpha), alpha;
      break;
  }
}

void attachment_motion(const Model& model, const Workspace& ws, const Attachment& A,
                       AttachmentMotion& out, bool jacobian) {
  const int n = model.n();
  if (jacobian) {
    out.Jv.resize(3, n);
    out.Jw.resize(3, n);
  }
  if (A.body < 0) {  // the world
    out.R = A.R;
    out.p = A.p - ws.origin;  // (from the reference point, as the bodies' places)
    out.v.setZero(), out.w.setZero(), out.a.setZero(), out.alpha.setZero();
    if (jacobian) out.Jv.setZero(), out.Jw.setZero();
    return;
  }
  const BodyState& B = ws.body[A.body];
  const Vec3 r = B.R * A.p;
  out.R = B.R * A.R;
  out.p = B.p + r;
  out.w = B.w;
  out.v = B.v + B.w.cross(r);
  out.alpha = B.alpha;
  out.a = B.a + B.alpha.cross(r) + B.w.cross(B.w.cross(r));
  if (!jacobian) return;
  out.Jw = ws.Jw.middleRows<3>(3 * A.body);
  out.Jv = ws.Jv.middleRows<3>(3 * A.body);
  out.Jv.noalias() -= skew(r) * out.Jw;
}

const char* frame_axes_name(FrameAxes axes) {
  switch (axes) {
    case FrameAxes::Local:
      return "local";
    case FrameAxes::World:
      return "world";
    case FrameAxes::LocalWorldAligned:
      break;
  }
  return "local_world_aligned";
}

bool parse_frame_axes(const std::string& text, FrameAxes& axes) {
  for (FrameAxes a : {FrameAxes::LocalWorldAligned, FrameAxes::Local, FrameAxes::World})
    if (text == frame_axes_name(a)) {
      axes = a;
      return true;
    }
  return false;
}

}  // namespace femdyn
