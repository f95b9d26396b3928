#include "core/derivatives/constraint_derivatives.hpp"

#include "core/derivatives/derivatives.hpp"
#include "core/derivatives/points.hpp"
#include "core/dynamics/body_loads.hpp"
#include "core/joints/rotation.hpp"

namespace femdyn {

ConstraintDerivatives::ConstraintDerivatives(const Model& m)
    : G(MatX::Zero(m.n(), m.n())),
      Cq(MatX::Zero(m.constraint_rows, m.n())),
      Cv(MatX::Zero(m.constraint_rows, m.n())),
      marked(m.n(), 0),
      arm(m.n(), Vec3::Zero()) {
  rates.reserve(m.n());
  for (PlaceDerivatives* P : {&A, &B}) {
    for (Mat3X* X : {&P->dx, &P->turn, &P->dx_dot, &P->dw, &P->dx_ddot, &P->dalpha, &P->dx_ddot_v,
                     &P->dalpha_v})
      X->setZero(3, m.n());
    P->path.reserve(m.n());
  }
}

namespace {

// The place's pose and motion, and per rate r on its path:
//   δx = J_r(x), δθ = ω_r, δẋ = ∂v_O + ∂ω × x + ω × δx, δẍ = ∂a_O + ∂α × x + α × δx + ∂ω × ẋ
//   + ω × δẋ (∂V, ∂a the body's along θ_r), and along θ̇_r δẍ = ∂a_O + ∂α × x + ω_r × ẋ
//   + ω × J_r(x) (∂a the body's along θ̇_r).
void place_derivatives(const Model& m, const Workspace& ws, const DerivativeWorkspace& d,
                       const Attachment& at, PlaceDerivatives& P) {
  for (Mat3X* X :
       {&P.dx, &P.turn, &P.dx_dot, &P.dw, &P.dx_ddot, &P.dalpha, &P.dx_ddot_v, &P.dalpha_v})
    X->setZero();
  P.body = at.body;
  if (at.body < 0) {  // the world: fixed
    P.R = at.R;
    P.x = at.p - ws.origin;  // from the reference point (Workspace::origin)
    P.x_dot.setZero(), P.x_ddot.setZero(), P.w.setZero(), P.alpha.setZero();
    P.path.clear();
    return;
  }
  const BodyState& Bs = ws.body[at.body];
  P.R = Bs.R * at.R;
  P.x = Bs.p + Bs.R * at.p;
  const Vec6& V = d.V[at.body];
  const Vec6 a = d.a[at.body] - gravity_base_acceleration(m);  // the true acceleration
  P.w = V.head<3>();
  P.alpha = a.head<3>();
  P.x_dot = point_velocity(V, P.x);
  P.x_ddot = point_velocity(a, P.x) + P.w.cross(P.x_dot);
  rates_on_path(m, at.body, P.path);
  Vec6 dV, da;
  for (const int r : P.path) {
    const Vec6& S = d.S[r];
    const Vec3 dx = point_velocity(S, P.x);
    P.dx.col(r) = dx;
    P.turn.col(r) = S.head<3>();
    body_position_derivative(m, d, at.body, r, dV, da);
    const Vec3 dx_dot = point_velocity(dV, P.x) + P.w.cross(dx);
    P.dx_dot.col(r) = dx_dot;
    P.dw.col(r) = dV.head<3>();
    P.dx_ddot.col(r) = point_velocity(da, P.x) + P.alpha.cross(dx) + dV.head<3>().cross(P.x_dot) +
                       P.w.cross(dx_dot);
    P.dalpha.col(r) = da.head<3>();
    da = body_rate_derivative(m, d, at.body, r);
    P.dx_ddot_v.col(r) = point_velocity(da, P.x) + S.head<3>().cross(P.x_dot) + P.w.cross(dx);
    P.dalpha_v.col(r) = da.head<3>();
  }
}

// The rates on A's or B's path into out.rates: every other column of a row's variations is 0.
void rates_of_places(ConstraintDerivatives& out) {
  out.rates.clear();
  for (const std::vector<int>* path : {&out.A.path, &out.B.path})
    for (const int r : *path)
      if (!out.marked[r]) out.marked[r] = 1, out.rates.push_back(r);
  for (const int r : out.rates) out.marked[r] = 0;
}

// The two places' relative motion (d = x_A − x_B) and B's rotation.
struct Ends {
  Vec3 d, d_dot, d_ddot, w_B, alpha_B;
};

Ends ends(const PlaceDerivatives& A, const PlaceDerivatives& B) {
  return {A.x - B.x, A.x_dot - B.x_dot, A.x_ddot - B.x_ddot, B.w, B.alpha};
}

// Their variation along one coordinate: δd, δḋ, δd̈; the turnings δθ_A − δθ_B and δθ_B; δω, δα
// (A's less B's) and B's own.
struct Variation {
  Vec3 d, d_dot, d_ddot, turn, turn_B, w, w_B, alpha, alpha_B;
};

Variation along_q(const PlaceDerivatives& A, const PlaceDerivatives& B, int k) {
  return {A.dx.col(k) - B.dx.col(k),
          A.dx_dot.col(k) - B.dx_dot.col(k),
          A.dx_ddot.col(k) - B.dx_ddot.col(k),
          A.turn.col(k) - B.turn.col(k),
          B.turn.col(k),
          A.dw.col(k) - B.dw.col(k),
          B.dw.col(k),
          A.dalpha.col(k) - B.dalpha.col(k),
          B.dalpha.col(k)};
}

// Along v_k the places stay: δd = 0, δθ = 0; δḋ = Δ_k, δω = ω_k.
Variation along_v(const PlaceDerivatives& A, const PlaceDerivatives& B, int k) {
  return {Vec3::Zero(),
          A.dx.col(k) - B.dx.col(k),
          A.dx_ddot_v.col(k) - B.dx_ddot_v.col(k),
          Vec3::Zero(),
          Vec3::Zero(),
          A.turn.col(k) - B.turn.col(k),
          B.turn.col(k),
          A.dalpha_v.col(k) - B.dalpha_v.col(k),
          B.dalpha_v.col(k)};
}

// δΦ, δΦ̇, δΦ̈ of one row.
struct RowVariation {
  double phi = 0, phi_dot = 0, phi_ddot = 0;
  double c(double omega) const { return phi_ddot + 2 * omega * phi_dot + omega * omega * phi; }
};

// A row along g = R_B e: Φ = gᵀ d, Φ̇ = gᵀ ḋ + (ω_B × g)ᵀ d, Φ̈ = gᵀ d̈ + 2 (ω_B × g)ᵀ ḋ + hᵀ d
// with h = α_B × g + ω_B × (ω_B × g), varied with δg = δθ_B × g.
RowVariation along_axis(const Ends& s, const Vec3& g, const Variation& e) {
  const Vec3 dg = e.turn_B.cross(g);
  const Vec3 wg = s.w_B.cross(g), dwg = e.w_B.cross(g) + s.w_B.cross(dg);
  const Vec3 h = s.alpha_B.cross(g) + s.w_B.cross(wg);
  const Vec3 dh = e.alpha_B.cross(g) + s.alpha_B.cross(dg) + e.w_B.cross(wg) + s.w_B.cross(dwg);
  RowVariation r;
  r.phi = dg.dot(s.d) + g.dot(e.d);
  r.phi_dot = dg.dot(s.d_dot) + g.dot(e.d_dot) + dwg.dot(s.d) + wg.dot(e.d);
  r.phi_ddot = dg.dot(s.d_ddot) + g.dot(e.d_ddot) + 2 * (dwg.dot(s.d_dot) + wg.dot(e.d_dot)) +
               dh.dot(s.d) + h.dot(e.d);
  return r;
}

// Φ = |d| − L, Φ̇ = êᵀ ḋ, Φ̈ = êᵀ d̈ + (|ḋ|² − (êᵀ ḋ)²) / l, with δê = (δd − ê êᵀ δd) / l.
RowVariation along_distance(const Ends& s, const Variation& e) {
  const double l = s.d.norm();
  const Vec3 u = s.d / l;
  const double dl = u.dot(e.d), ld = u.dot(s.d_dot);
  const Vec3 du = (e.d - u * dl) / l;
  const double dld = du.dot(s.d_dot) + u.dot(e.d_dot);
  const double across = s.d_dot.squaredNorm() - ld * ld;
  RowVariation r;
  r.phi = dl;
  r.phi_dot = dld;
  r.phi_ddot = du.dot(s.d_ddot) + u.dot(e.d_ddot) + (2 * s.d_dot.dot(e.d_dot) - 2 * ld * dld) / l -
               across * dl / (l * l);
  return r;
}

// Row `row` of C_q and C_v from the row's variation along each coordinate.
template <class Row>
void fill_row(const PlaceDerivatives& A, const PlaceDerivatives& B, double omega, int row,
              ConstraintDerivatives& out, Row&& vary) {
  out.Cq.row(row).setZero();
  out.Cv.row(row).setZero();
  for (const int k : out.rates) {
    out.Cq(row, k) = vary(along_q(A, B, k)).c(omega);
    out.Cv(row, k) = vary(along_v(A, B, k)).c(omega);
  }
}

// G += ∂(λ_f ᵀ (J(x_A) − J(x_B)))/∂q at f fixed.
void add_force_turning(const Model& m, const DerivativeWorkspace& d, const Vec3& f,
                       ConstraintDerivatives& out) {
  add_point_turning(m, d, out.A.x, f, out.A.path, out.arm, out.G);
  add_point_turning(m, d, out.B.x, -f, out.B.path, out.arm, out.G);
}

void ball(const Model& m, const DerivativeWorkspace& d, const Vec3& lambda, double omega, int row,
          ConstraintDerivatives& out) {
  const PlaceDerivatives &A = out.A, &B = out.B;
  out.Cq.middleRows<3>(row).setZero();
  out.Cv.middleRows<3>(row).setZero();
  for (const int k : out.rates) {
    const Variation q = along_q(A, B, k), v = along_v(A, B, k);
    out.Cq.block<3, 1>(row, k) = q.d_ddot + 2 * omega * q.d_dot + omega * omega * q.d;
    out.Cv.block<3, 1>(row, k) = v.d_ddot + 2 * omega * v.d_dot;
  }
  add_force_turning(m, d, lambda, out);
}

void rows_along_axes(const Model& m, const DerivativeWorkspace& d, const LoopConstraint& c,
                     const VecX& lambda, double omega, int row, ConstraintDerivatives& out) {
  const PlaceDerivatives &A = out.A, &B = out.B;
  const Ends s = ends(A, B);
  Vec3 force = Vec3::Zero();  // f = Σ_i λ_i g_i
  for (std::size_t i = 0; i < c.axes.size(); ++i) {
    const Vec3 g = B.R * c.axes[i];
    fill_row(A, B, omega, row + static_cast<int>(i), out,
             [&](const Variation& e) { return along_axis(s, g, e); });
    force += lambda[row + static_cast<int>(i)] * g;
  }
  // The turning of the rows themselves, Σ_i λ_i [(δg_i,k)ᵀ Δ_c + (δg_i,k × d + g_i × Δ_k)ᵀ ω_B,c]
  // with δg_i,k = ω_B,k × g_i: that of the force f, δf_k = ω_B,k × f,
  //   G(c, k) += δf_kᵀ Δ_c + (δf_k × d + f × Δ_k)ᵀ ω_B,c.
  for (const int k : out.rates) {
    const Vec3 df = B.turn.col(k).cross(force), delta_k = A.dx.col(k) - B.dx.col(k);
    const Vec3 dt = df.cross(s.d) + force.cross(delta_k);
    for (const int col : out.rates)
      out.G(col, k) += df.dot(A.dx.col(col) - B.dx.col(col)) + dt.dot(B.turn.col(col));
  }
  add_force_turning(m, d, force, out);
  add_axis_turning(m, d, force.cross(s.d), B.path, out.G);  // λ (g × d)ᵀ Jω_B
}

// The weld's angle rows (its first three are a ball's).
void weld_angles(const Model& m, const DerivativeWorkspace& d, const Vec3& lambda, double omega,
                 int row, ConstraintDerivatives& out) {
  const PlaceDerivatives &A = out.A, &B = out.B;
  const Eigen::AngleAxisd rel(B.R.transpose() * A.R);
  const Vec3 phi = B.R * (rel.angle() * rel.axis());
  out.Cq.middleRows<3>(row).setZero();
  out.Cv.middleRows<3>(row).setZero();
  for (const int k : out.rates) {
    const Variation q = along_q(A, B, k), v = along_v(A, B, k);
    const Vec3 dphi = inverse_right_jacobian_times(-phi, q.turn) - phi.cross(q.turn_B);
    out.Cq.block<3, 1>(row, k) = q.alpha + 2 * omega * q.w + omega * omega * dphi;
    out.Cv.block<3, 1>(row, k) = v.alpha + 2 * omega * v.w;
  }
  add_axis_turning(m, d, lambda, A.path, out.G);
  add_axis_turning(m, d, -lambda, B.path, out.G);
}

void distance(const Model& m, const DerivativeWorkspace& d, double lambda, double omega, int row,
              ConstraintDerivatives& out) {
  const PlaceDerivatives &A = out.A, &B = out.B;
  const Ends s = ends(A, B);
  const double l = s.d.norm();
  if (!(l > 0)) {  // coincident ends: a singular row, refused by the solve
    out.Cq.row(row).setZero();
    out.Cv.row(row).setZero();
    return;
  }
  fill_row(A, B, omega, row, out, [&](const Variation& e) { return along_distance(s, e); });
  const Vec3 u = s.d / l;
  add_force_turning(m, d, lambda * u, out);
  for (const int k : out.rates) {  // λ (δê_k)ᵀ Δ_c
    const Vec3 delta_k = A.dx.col(k) - B.dx.col(k);
    const Vec3 du = (delta_k - u * u.dot(delta_k)) / l;
    for (const int col : out.rates) out.G(col, k) += lambda * du.dot(A.dx.col(col) - B.dx.col(col));
  }
}

// Φ_q constant: C_q = ω² Φ_q, C_v = 2ω Φ_q.
void gear(const LoopConstraint& c, double omega, int row, ConstraintDerivatives& out) {
  out.Cq.row(row) = omega * omega * c.gear_rate.transpose();
  out.Cv.row(row) = 2 * omega * c.gear_rate.transpose();
}

}  // namespace

void constraint_derivatives(const Model& m, const Workspace& ws, const DerivativeWorkspace& d,
                            const VecX& lambda, double omega, ConstraintDerivatives& out) {
  out.G.setZero();
  int row = 0;
  for (const LoopConstraint& c : m.constraints) {
    if (c.type != ConstraintType::Gear) {
      place_derivatives(m, ws, d, c.a, out.A);
      place_derivatives(m, ws, d, c.b, out.B);
      rates_of_places(out);
    }
    switch (c.type) {
      case ConstraintType::Ball:
        if (c.axes.empty())
          ball(m, d, lambda.segment<3>(row), omega, row, out);
        else
          rows_along_axes(m, d, c, lambda, omega, row, out);
        break;
      case ConstraintType::PointOnLine:
      case ConstraintType::PointOnPlane:
        rows_along_axes(m, d, c, lambda, omega, row, out);
        break;
      case ConstraintType::Weld:
        ball(m, d, lambda.segment<3>(row), omega, row, out);
        weld_angles(m, d, lambda.segment<3>(row + 3), omega, row + 3, out);
        break;
      case ConstraintType::Distance:
        distance(m, d, lambda[row], omega, row, out);
        break;
      case ConstraintType::Gear:
        gear(c, omega, row, out);
        break;
    }
    row += c.rows();
  }
}

}  // namespace femdyn
