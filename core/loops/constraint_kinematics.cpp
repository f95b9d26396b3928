#include "core/loops/constraint_kinematics.hpp"

#include <cmath>

#include "core/joints/rotation.hpp"
#include "core/kinematics/kinematics.hpp"

namespace femdyn {

namespace {

// Rows along axes g = R_B e (ball in a plane, point on line, point on plane).
void rows_along_axes(const LoopConstraint& c, ConstraintKinematics& k, int row) {
  const AttachmentMotion &A = k.A, &B = k.B;
  const Vec3 d = A.p - B.p, dd = A.v - B.v, d0 = A.a - B.a;
  for (const Vec3& e : c.axes) {
    const Vec3 g = B.R * e, wg = B.w.cross(g);
    k.phi[row] = g.dot(d);
    // (term by term: a product with A.Jv − B.Jv would allocate that difference)
    k.J.row(row).noalias() = g.transpose() * A.Jv;
    k.J.row(row).noalias() -= g.transpose() * B.Jv;
    k.J.row(row).noalias() += g.cross(d).transpose() * B.Jw;
    k.bias[row] = g.dot(d0) + 2 * wg.dot(dd) + (B.alpha.cross(g) + B.w.cross(wg)).dot(d);
    ++row;
  }
}

void ball_rows(ConstraintKinematics& k, int row) {
  const AttachmentMotion &A = k.A, &B = k.B;
  k.phi.segment<3>(row) = A.p - B.p;
  k.J.middleRows<3>(row) = A.Jv - B.Jv;
  k.bias.segment<3>(row) = A.a - B.a;
}

// The weld's angles: the rotation vector of R_Bᵀ R_A in world axes; its rate ω_A − ω_B.
void weld_angle_rows(ConstraintKinematics& k, int row) {
  const AttachmentMotion &A = k.A, &B = k.B;
  const Eigen::AngleAxisd rel(B.R.transpose() * A.R);
  k.phi.segment<3>(row) = B.R * (rel.angle() * rel.axis());
  k.J.middleRows<3>(row) = A.Jw - B.Jw;
  k.bias.segment<3>(row) = A.alpha - B.alpha;
}

void distance_row(const LoopConstraint& c, ConstraintKinematics& k, int row) {
  const AttachmentMotion &A = k.A, &B = k.B;
  const Vec3 d = A.p - B.p, dd = A.v - B.v;
  const double l = d.norm();
  k.phi[row] = l - c.length;
  if (!(l > 0)) {  // coincident ends: no direction, a singular row (diagnosed by the solve)
    k.J.row(row).setZero();
    k.bias[row] = 0;
    return;
  }
  const Vec3 e = d / l;
  const double ld = e.dot(dd);
  k.J.row(row).noalias() = e.transpose() * A.Jv;
  k.J.row(row).noalias() -= e.transpose() * B.Jv;
  k.bias[row] = e.dot(A.a - B.a) + (dd.squaredNorm() - ld * ld) / l;
}

void gear_row(const Workspace& ws, const LoopConstraint& c, ConstraintKinematics& k, int row) {
  double phi = ws.theta[c.joint] - c.offset;
  for (const auto& [i, ratio] : c.terms) phi -= ratio * ws.theta[i];
  k.phi[row] = phi;
  k.J.row(row) = c.gear_rate.transpose();
  k.bias[row] = 0;
}

}  // namespace

ConstraintKinematics::ConstraintKinematics(const Model& model)
    : phi(VecX::Zero(model.constraint_rows)),
      J(MatX::Zero(model.constraint_rows, model.n())),
      bias(VecX::Zero(model.constraint_rows)) {}

namespace {

// Jω and Jv of the attachment's point p (world) on `body`, by the body's path to the root: each
// rate j on it turns about or slides along its spatial column S_j = (ω_j, v_j) (world axes,
// about the origin), so Jω_:j = ω_j and Jv_:j = v_j + ω_j × p. O(depth) after an O(n) clear.
void path_jacobian(const Model& model, const Workspace& ws, int body, const Vec3& p,
                   AttachmentMotion& out) {
  out.Jw.setZero(3, model.n());
  out.Jv.setZero(3, model.n());
  for (int b = body; b >= 0; b = model.bodies[b].parent) {
    const Joint& J = model.bodies[b].joint;
    for (int k = 0; k < J.nv; ++k) {
      const Vec6& S = J.nv == 1 ? ws.articulated[b].S : ws.subspace[J.idx_v + k];
      out.Jw.col(J.idx_v + k) = S.head<3>();
      out.Jv.col(J.idx_v + k) = S.tail<3>() + S.head<3>().cross(p);
    }
  }
}

// Each constraint's two attachments into k.A, k.B (none for a gear), then its rows.
template <class Attach>
void constraint_rows(const Model& model, const Workspace& ws, ConstraintKinematics& k,
                     Attach&& attach) {
  int row = 0;
  for (const LoopConstraint& c : model.constraints) {
    if (c.type != ConstraintType::Gear) {
      attach(c.a, k.A);
      attach(c.b, k.B);
    }
    switch (c.type) {
      case ConstraintType::Ball:
        if (c.axes.empty())
          ball_rows(k, row);
        else
          rows_along_axes(c, k, row);
        break;
      case ConstraintType::PointOnLine:
      case ConstraintType::PointOnPlane:
        rows_along_axes(c, k, row);
        break;
      case ConstraintType::Weld:
        ball_rows(k, row);
        weld_angle_rows(k, row + 3);
        break;
      case ConstraintType::Distance:
        distance_row(c, k, row);
        break;
      case ConstraintType::Gear:
        gear_row(ws, c, k, row);
        break;
    }
    row += c.rows();
  }
}

}  // namespace

void constraint_kinematics(const Model& model, const Workspace& ws, ConstraintKinematics& k) {
  constraint_rows(model, ws, k, [&](const Attachment& a, AttachmentMotion& out) {
    attachment_motion(model, ws, a, out);
  });
}

void constraint_kinematics_by_paths(const Model& model, const Workspace& ws,
                                    ConstraintKinematics& k) {
  constraint_rows(model, ws, k, [&](const Attachment& a, AttachmentMotion& out) {
    attachment_motion(model, ws, a, out, false);
    if (a.body >= 0)
      path_jacobian(model, ws, a.body, out.p, out);
    else
      out.Jw.setZero(3, model.n()), out.Jv.setZero(3, model.n());
  });
}

void constraint_kinematics(const Model& model, Workspace& ws, const VecX& q, const VecX& v,
                           ConstraintKinematics& k) {
  propagate(model, ws, q, v, {.jacobian = true, .bias = true, .rows = false});
  constraint_kinematics(model, ws, k);
}

std::string constraint_row_name(const Model& model, int i) {
  for (const LoopConstraint& c : model.constraints) {
    if (i < c.rows()) return c.rows() == 1 ? c.name : c.name + "[" + std::to_string(i) + "]";
    i -= c.rows();
  }
  return "?";
}

}  // namespace femdyn
