#include "core/dynamics/span_inertia.hpp"

#include <algorithm>

#include "core/joints/kernel.hpp"
#include "core/model/model.hpp"
#include "core/workspace/workspace.hpp"

namespace femdyn {
namespace {

// Whether the element uses only its translation at this node.
bool translations_only(const ElementNode& node) {
  return std::none_of(node.uses.begin() + 3, node.uses.end(), [](bool u) { return u; });
}

// The last rate on body b's path to the world (−1: none); the others follow by rate_parent.
int last_rate(const Model& m, int b) {
  for (; b >= 0; b = m.bodies[b].parent)
    if (const Joint& J = m.bodies[b].joint; moves(J)) return J.idx_v + J.nv - 1;
  return -1;
}

// x = p + R r, the node's place in world axes.
Vec3 node_position(const Workspace& ws, const SpanningMass& s, int l) {
  const BodyState& B = ws.body[s.body[l]];
  return B.p + B.R * s.point[l];
}

// J_c(x) = v_c + ω_c × x.
Vec3 column_at(const Vec6& S, const Vec3& x) { return S.tail<3>() + S.head<3>().cross(x); }

// ẍ = a_O + α × x + ω × ẋ, ẋ = v_O + ω × x, from the body's world-origin motion V, a.
Vec3 node_acceleration(const Workspace& ws, const SpanningMass& s, int l) {
  const Vec3 x = node_position(ws, s, l);
  const Vec6& V = ws.articulated[s.body[l]].V;
  const Vec6& a = ws.articulated[s.body[l]].a;
  const Vec3 x_dot = V.tail<3>() + V.head<3>().cross(x);
  return a.tail<3>() + a.head<3>().cross(x) + V.head<3>().cross(x_dot);
}

}  // namespace

std::string span_inertia_unsupported(const Model& m) {
  for (const ElementEntry& e : m.elements) {
    if (!e.spans) continue;
    const auto nodes = e.element->nodes();
    if (e.element->has_velocity_force() ||
        !std::all_of(nodes.begin(), nodes.end(), translations_only))
      return e.where +
             ": an element spanning bodies that uses its nodes' rotations or has a "
             "velocity force";
  }
  return "";
}

std::vector<SpanningMass> spanning_masses(const Model& m) {
  std::vector<SpanningMass> out;
  for (const ElementEntry& e : m.elements) {
    if (!e.spans) continue;
    const auto nodes = e.element->nodes();
    const MatX me = e.element->local_mass();
    const int k = static_cast<int>(nodes.size());
    SpanningMass s;
    s.mass.resize(3 * k, 3 * k);  // the translation rows and columns of m_e
    for (int l = 0; l < k; ++l) {
      s.body.push_back(e.node_body[l]);
      s.point.push_back(nodes[l].position);
      for (int j = 0; j < k; ++j) s.mass.block<3, 3>(3 * l, 3 * j) = me.block<3, 3>(6 * l, 6 * j);
    }
    out.push_back(std::move(s));
  }
  return out;
}

// Σ_lj J_lᵀ M_lj J_j over the pairs l ≤ j (M_jl = M_ljᵀ: the pair (j, l) gives the transposed
// entries). A column's product with M_lj is a force u at x_j, whose work on rate r is the
// spatial product S_rᵀ (x_j × u, u): one cross product per column c, six products per entry.
void add_span_mass(const Model& m, Workspace& ws) {
  for (const SpanningMass& s : m.spanning_masses) {
    const int k = static_cast<int>(s.body.size());
    for (int l = 0; l < k; ++l) {
      const Vec3 xl = node_position(ws, s, l);
      for (int j = l; j < k; ++j) {
        const Vec3 xj = node_position(ws, s, j);
        const Mat3 Mlj_T = s.mass.block<3, 3>(3 * l, 3 * j).transpose();
        for (int c = last_rate(m, s.body[l]); c >= 0; c = m.rate_parent[c]) {
          Vec6 f;  // the force M_ljᵀ J_c(x_l) at x_j, as a spatial force about the origin
          f.tail<3>().noalias() = Mlj_T * column_at(ws.subspace[c], xl);
          f.head<3>() = xj.cross(f.tail<3>());
          for (int r = last_rate(m, s.body[j]); r >= 0; r = m.rate_parent[r]) {
            const double v = ws.subspace[r].dot(f);
            ws.Ms(c, r) += v;
            if (j != l) ws.Ms(r, c) += v;
          }
        }
      }
    }
  }
}

void add_span_forces(const Model& m, const Workspace& ws, VecX& y) {
  for (const SpanningMass& s : m.spanning_masses) {
    const int k = static_cast<int>(s.body.size());
    for (int l = 0; l < k; ++l) {
      Vec3 F = Vec3::Zero();  // F_l = Σ_j M_lj ẍ_j
      for (int j = 0; j < k; ++j)
        F += s.mass.block<3, 3>(3 * l, 3 * j) * node_acceleration(ws, s, j);
      const Vec3 x = node_position(ws, s, l);
      for (int c = last_rate(m, s.body[l]); c >= 0; c = m.rate_parent[c])
        y[c] += column_at(ws.subspace[c], x).dot(F);
    }
  }
}

double span_kinetic_energy(const Model& m, const Workspace& ws) {
  double T = 0;
  for (const SpanningMass& s : m.spanning_masses) {
    const int k = static_cast<int>(s.body.size());
    const auto velocity = [&](int l) {
      const BodyState& B = ws.body[s.body[l]];
      return Vec3(B.v + B.w.cross(B.R * s.point[l]));
    };
    for (int l = 0; l < k; ++l)
      for (int j = 0; j < k; ++j)
        T += 0.5 * velocity(l).dot(s.mass.block<3, 3>(3 * l, 3 * j) * velocity(j));
  }
  return T;
}

}  // namespace femdyn
