#include "compile/correlation.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <random>
#include <tuple>

#include "core/dynamics/equations.hpp"
#include "core/joints/kernel.hpp"
#include "core/kinematics/kinematics.hpp"
#include "core/kinematics/sampling.hpp"
#include "core/model/errors.hpp"
#include "core/model/limits.hpp"
#include "core/model/names.hpp"

namespace femdyn {
namespace {

// The shallowest body on which a point of body b stays fixed: a point on a revolute axis, or
// behind a fixed joint, moves with the parent too. Coincident element nodes thus share one
// system node, as at the paper's hinges.
std::pair<int, Vec3> canonical_point(const Model& m, int b, Vec3 r) {
  while (m.bodies[b].parent >= 0) {
    const Joint& j = m.bodies[b].joint;
    if (!fixes_point(j, r)) break;
    Mat3 R;
    Vec3 p;
    neutral_pose(j, R, p);  // the point is where it is at any θ_J
    r = R * r + p;
    b = m.bodies[b].parent;
  }
  return {b, r};
}

// nodes_of[b]: the system nodes on body b, so that a lookup scans one body's nodes only.
using NodesOfBody = std::vector<std::vector<int>>;

int find_or_add_node(Model& m, NodesOfBody& nodes_of, int body, const Vec3& r_body,
                     const std::string& label) {
  const auto [b, r] = canonical_point(m, body, r_body);
  for (const int i : nodes_of[b])
    if ((m.nodes[i].r - r).norm() <= 1e-12 * (1.0 + r.norm())) return i;
  m.nodes.push_back({b, r, label});
  nodes_of[b].push_back(static_cast<int>(m.nodes.size()) - 1);
  return static_cast<int>(m.nodes.size()) - 1;
}

// Candidate transition coordinates, numbered in order of first use.
struct Candidates {
  std::vector<SystemDof> list;
  std::vector<bool> needed;  // used by an element or a load
  std::map<std::tuple<int, int, int>, int> index;
  int add(DofKind kind, int carrier, int axis, bool use) {
    auto key = std::make_tuple(static_cast<int>(kind), carrier, axis);
    auto [it, fresh] = index.emplace(key, static_cast<int>(list.size()));
    if (fresh) {
      list.push_back({kind, carrier, axis});
      needed.push_back(false);
    }
    if (use) needed[it->second] = true;
    return it->second;
  }
};

void set_dofs(Model& m, const std::vector<SystemDof>& dofs) {
  m.dofs = dofs;
  m.node_dof.assign(m.nodes.size(), {-1, -1, -1});
  m.body_rot_dof.assign(m.bodies.size(), {-1, -1, -1});
  m.dof_alias.clear();
  for (std::size_t i = 0; i < dofs.size(); ++i) {
    auto& slot = dofs[i].kind == DofKind::Translation ? m.node_dof[dofs[i].carrier]
                                                      : m.body_rot_dof[dofs[i].carrier];
    if (slot[dofs[i].axis] >= 0)
      m.dof_alias.emplace_back(static_cast<int>(i), slot[dofs[i].axis]);
    else
      slot[dofs[i].axis] = static_cast<int>(i);
  }
}

// Rows of T at seeded random states: a row that is zero at all of them is a DOF that never
// moves (T is analytic in q, so a non-zero row vanishes only on a set of measure zero).
// `row_max` is the largest |T_ia| of each row over the samples (or, by paths, a value above the
// tolerance as soon as one is found); the samples themselves are kept
// only when an explicit table must be checked motion by motion (they are N_u x n each).
double length_scale(const Model& m) {
  double L = 1.0;
  for (const Body& b : m.bodies) L = std::max(L, b.joint.p_pj.norm());
  for (const SystemNode& n : m.nodes) L = std::max(L, n.r.norm());
  return L;
}

struct TSamples {
  VecX row_max;
  std::vector<MatX> T;
};

// Without a coupling (C = I) and without keeping the samples, the rows are not formed: each
// DOF's largest |T_ia| is taken over the joints a on its carrier's path, with the body poses
// of one sweep,
//   translation k of a node at x:  revolute (s_a × (x − o_a))_k,  prismatic (s_a)_k
//   rotation k of body b:           revolute (R_b e_k)·s_a,        prismatic 0,
// Each entry is a linear functional of a column of the joint's motion subspace, as a spatial
// motion S_a (core/joints/kernel.hpp; revolute (s_a, o_a × s_a)): T_ia = S_a · w_i with w = (x ×
// e_k, e_k) for a translation, (R_b e_k, 0) for a rotation. So the whole row is bounded by |P_b w|
// · max_a |S_a|, P_b the projector on the span of the S_a along the path, kept per body as an
// orthonormal basis of at most six vectors (O(1) per body). A row under the tolerance by that bound
// (every left-out DOF, e.g. the z of a planar chain) costs O(1); otherwise the path is scanned,
// stopping at the first entry above `enough` (only whether a row exceeds the tolerance is used),
// which for a DOF that moves is near its own body. O(N_u + bodies) time, O(N_u + bodies) memory
// instead of the dense N_u × n T.
struct PathSpan {
  std::array<Vec6, 6> basis;  // orthonormal
  int size = 0;
  double s_max = 0;                    // max |S_a| on the path
  double bound(const Vec6& w) const {  // |P w| · max |S_a|
    Vec6 p = Vec6::Zero();
    for (int k = 0; k < size; ++k) p += basis[k].dot(w) * basis[k];
    return p.norm() * s_max;
  }
};

// The span of the joint columns S_a on each body's path from the world, parents first.
void path_spans(const Model& m, const Workspace& ws, std::vector<PathSpan>& span) {
  const int nb = static_cast<int>(m.bodies.size());
  for (int b = 0; b < nb; ++b) {  // parents first
    const Body& B = m.bodies[b];
    span[b] = B.parent >= 0 ? span[B.parent] : PathSpan{};
    for (int c = 0; c < B.joint.nv; ++c) {
      const Vec6 S =
          spatial_column(B.joint, ws.body[b].R, parent_rotation(m, ws.body, b), ws.body[b].p, c);
      PathSpan& P = span[b];
      P.s_max = std::max(P.s_max, S.norm());
      Vec6 r = S;  // Gram–Schmidt, twice for orthogonality in floating point
      for (int pass = 0; pass < 2; ++pass)
        for (int k = 0; k < P.size; ++k) r -= P.basis[k].dot(r) * P.basis[k];
      if (P.size < 6 && r.norm() > 1e-9 * S.norm()) P.basis[P.size++] = r.normalized();
    }
  }
}

void row_max_by_paths(const Model& m, Workspace& ws, std::vector<PathSpan>& span, VecX& row_max,
                      double enough) {
  path_spans(m, ws, span);
  // max |T_ia| = max |S_a · w| over the columns a of the joints on the path.
  const auto over_path = [&](int body, const Vec6& w) {
    double big = 0;
    for (int a = body; a >= 0 && big <= enough; a = m.bodies[a].parent)
      for (int c = 0; c < m.bodies[a].joint.nv; ++c)
        big = std::max(big, std::abs(spatial_column(m.bodies[a].joint, ws.body[a].R,
                                                    parent_rotation(m, ws.body, a), ws.body[a].p, c)
                                         .dot(w)));
    return big;
  };
  for (int i = 0; i < m.n_u(); ++i) {
    const SystemDof& d = m.dofs[i];
    double big;
    Vec6 w;
    if (d.kind == DofKind::Translation) {
      const SystemNode& node = m.nodes[d.carrier];
      const Vec3 x = ws.body[node.body].p + ws.body[node.body].R * node.r;
      const Vec3 e = Vec3::Unit(d.axis);
      w << x.cross(e), e;
      big = span[node.body].bound(w);
      if (big > enough) big = over_path(node.body, w);
    } else {
      const Vec3 e = ws.body[d.carrier].R.col(d.axis);
      w << e, Vec3::Zero();
      big = span[d.carrier].bound(w);
      if (big > enough) big = over_path(d.carrier, w);
    }
    row_max[i] = std::max(row_max[i], big);
  }
}

TSamples sample_T(const Model& m, bool keep, double tol) {
  TSamples out;
  out.row_max = VecX::Zero(m.n_u());
  Workspace ws(m);
  const bool by_paths = !keep && m.identity_coupling;
  std::vector<PathSpan> span(by_paths ? m.bodies.size() : 0);
  for (const VecX& q : sample_states(m, 3)) {
    if (by_paths) {
      propagate(m, ws, q, q, {.jacobian = false, .bias = false, .rows = false});
      row_max_by_paths(m, ws, span, out.row_max, tol);
      continue;
    }
    propagate(m, ws, q, VecX::Zero(m.n()), {.jacobian = true, .bias = false});
    if (m.n() > 0) out.row_max = out.row_max.cwiseMax(ws.T.cwiseAbs().rowwise().maxCoeff());
    if (keep) out.T.push_back(ws.T);
  }
  return out;
}

bool moves(const TSamples& Ts, int i, double tol) { return Ts.row_max[i] > tol; }

bool same_motion(const TSamples& Ts, int i, int j, double tol) {
  for (const MatX& T : Ts.T)
    if ((T.row(i) - T.row(j)).cwiseAbs().maxCoeff() > tol) return false;
  return true;
}

int carrier_body(const Model& m, const SystemDof& d) {
  return d.kind == DofKind::Translation ? m.nodes[d.carrier].body : d.carrier;
}

int depth(const Model& m, int body) {
  int k = 0;
  for (int b = body; b >= 0; b = m.bodies[b].parent) ++k;
  return k;
}

// The node level of a compiled tree (Model::elements, nodes, dofs, M, F_constant), built in
// passes: each element's nodes and their candidate transition coordinates, the loads' points,
// the system DOFs numbered (those that move, or an explicit table's), then M = Σ_e scatter(m_e)
// through N_m and F = M G + the loads.
class NodeLevel {
 public:
  NodeLevel(MechanismSpec& spec, Model& m) : spec(spec), m(m), nodes_of(m.bodies.size()) {}

  void build(const std::vector<int>& body_of_spec) {
    place_elements(body_of_spec);
    place_loads();
    set_dofs(m, cand.list);  // which candidates move at all
    tol = 1e-10 * length_scale(m);
    Ts = sample_T(m, spec.correlation.has_value(), tol);
    set_dofs(m, spec.correlation ? number_by_table(*spec.correlation) : number_moving());
    check_loads_kept();
    assemble_mass();
    constant_forces();
  }

 private:
  // A load, with the node and body whose DOFs it pushes on.
  struct LoadAt {
    int node, body;
    Vec3 force, torque;
    std::string where;
  };

  MechanismSpec& spec;
  Model& m;
  Candidates cand;
  NodesOfBody nodes_of;
  std::vector<std::vector<int>> local_cand;  // per element: 6k, -1 where unused
  std::vector<std::vector<int>> all_cand;    // per element: 6k, also for unused local DOFs
  std::map<std::string, int> body_named;
  std::vector<LoadAt> loads;
  double tol = 0;  // a row of T below it never moves
  TSamples Ts;

  // The body a node label "other_body/node" names (an element that spans bodies), else `own`.
  int body_of_label(const std::string& label, int own) const {
    for (std::size_t cut = label.rfind('/'); cut != std::string::npos && cut > 0;
         cut = label.rfind('/', cut - 1)) {
      const auto it = body_named.find(label.substr(0, cut));
      if (it != body_named.end()) return it->second;
    }
    return own;
  }

  // Elements in file order; each local DOF gets its candidate transition coordinate.
  void place_elements(const std::vector<int>& body_of_spec) {
    for (std::size_t k = 0; k < m.bodies.size(); ++k)
      body_named.emplace(m.bodies[k].name, static_cast<int>(k));
    for (std::size_t s = 0; s < spec.bodies.size(); ++s)
      for (ElementSpec& es : spec.bodies[s].elements) place_element(es, body_of_spec[s]);
  }

  void place_element(ElementSpec& es, int b) {
    ElementEntry e;
    e.element = std::move(es.element);
    e.body = b;
    e.where = es.where;
    e.node_labels = es.node_labels;
    const auto nodes = e.element->nodes();
    std::vector<int> used, all;
    for (std::size_t l = 0; l < nodes.size(); ++l) {
      std::string label = l < es.node_labels.size() ? es.node_labels[l] : "node";
      check_name(label, es.where, "node label");
      if (label.find('/') == std::string::npos) label = m.bodies[b].name + "/" + label;
      check_magnitude(nodes[l].position, es.where, "element node position");
      const int nb = body_of_label(label, b);
      if (nb != b) {
        e.spans = true;
        for (int k = 3; k < kNodeDofs; ++k)
          if (nodes[l].uses[k])
            throw ModelError(es.where, "node '" + label +
                                           "' is on another body: an element uses only its "
                                           "translation there (no rotation)");
      }
      e.node_body.push_back(nb);
      const int node = find_or_add_node(m, nodes_of, nb, nodes[l].position, label);
      for (int k = 0; k < kNodeDofs; ++k) {
        const bool use = nodes[l].uses[k];
        const int c = k < 3 ? cand.add(DofKind::Translation, node, k, use)
                            : cand.add(DofKind::Rotation, b, k - 3, use);
        all.push_back(c);
        used.push_back(use ? c : -1);
      }
    }
    check_local_mass(*e.element, es.where);
    local_cand.push_back(std::move(used));
    all_cand.push_back(std::move(all));
    m.elements.push_back(std::move(e));
  }

  static void check_local_mass(const Element& element, const std::string& where) {
    const MatX me = element.local_mass();
    if (me.rows() != element.local_dof_count() || me.cols() != me.rows() || !me.allFinite() ||
        (me - me.transpose()).norm() > 1e-12 * (1.0 + me.norm()))
      throw ModelError(where, "element local mass is not a finite symmetric matrix");
  }

  // Loads need the DOFs they push on.
  void place_loads() {
    for (const LoadSpec& ls : spec.loads) {
      const auto found = body_named.find(ls.body);
      if (found == body_named.end())
        throw ModelError(ls.where + "/body", "unknown body " + quoted_text(ls.body));
      const int b = found->second;
      check_magnitude(ls.point, ls.where + "/point", "load point");
      check_magnitude(ls.force, ls.where + "/force", "load force");
      check_magnitude(ls.torque, ls.where + "/torque", "load torque");
      const int node = find_or_add_node(m, nodes_of, b, ls.point, ls.body + "/load");
      if (!ls.force.isZero(0))
        for (int k = 0; k < 3; ++k) cand.add(DofKind::Translation, node, k, true);
      if (!ls.torque.isZero(0))
        for (int k = 0; k < 3; ++k) cand.add(DofKind::Rotation, b, k, true);
      loads.push_back({node, b, ls.force, ls.torque, ls.where});
      if (!ls.force.isZero(0)) m.point_loads.push_back({b, ls.point, ls.force});
    }
  }

  // The system DOFs without a table: every needed candidate that moves, in order. A DOF that
  // moves above round-off (1e-13 L) but below the cut-off is left out too: an approximation
  // (an axis tilted by 3.5e-10 rad by rpy="3.141592654"), listed as one.
  std::vector<SystemDof> number_moving() {
    const int nc = static_cast<int>(cand.list.size());
    std::vector<int> number(nc, 0);  // candidate -> 1-based system DOF, 0 left out
    std::vector<SystemDof> dofs;
    std::vector<std::string> barely;
    double barely_max = 0;
    for (int c = 0; c < nc; ++c) {
      if (!cand.needed[c]) continue;
      if (moves(Ts, c, tol)) {
        dofs.push_back(cand.list[c]);
        number[c] = static_cast<int>(dofs.size());
        continue;
      }
      m.left_out.push_back(m.dof_name_of(cand.list[c]) + " (never moves)");
      if (moves(Ts, c, 1e-3 * tol)) {
        barely.push_back(m.dof_name_of(cand.list[c]));
        barely_max = std::max(barely_max, Ts.row_max[c]);
      }
    }
    if (!barely.empty()) note_barely_moving(barely, barely_max);
    for (std::size_t e = 0; e < m.elements.size(); ++e)
      for (int c : local_cand[e]) m.elements[e].table_row.push_back(c >= 0 ? number[c] : 0);
    return dofs;
  }

  void note_barely_moving(const std::vector<std::string>& barely, double barely_max) {
    std::string list;
    for (std::size_t k = 0; k < barely.size() && k < 5; ++k) list += (k ? ", " : "") + barely[k];
    if (barely.size() > 5) list += ", … (" + std::to_string(barely.size()) + " in all)";
    m.approximations.push_back(list + ": moves by at most " + format_sci(barely_max) +
                               " per unit rate, below the cut-off " + format_sci(tol) +
                               ", and is treated as never moving (its terms, gravity's "
                               "included, are dropped)");
  }

  // Explicit N_m, checked: each number must name one physical motion.
  std::vector<SystemDof> number_by_table(const CorrelationSpec& cs) {
    m.explicit_table = true;
    const int N = table_size(cs);
    std::vector<int> def(N + 1, -1);                  // system DOF -> defining candidate
    std::vector<std::pair<int, std::string>> joined;  // approximate joins (join_deepest)
    for (std::size_t e = 0; e < cs.rows.size(); ++e)
      for (std::size_t l = 0; l < cs.rows[e].size(); ++l) define_by_table(cs, e, l, def, joined);
    for (const auto& [d, joins] : joined)
      m.approximations.push_back(joins + ": takes " + m.dof_name_of(cand.list[def[d]]));
    std::vector<SystemDof> dofs;
    for (int d = 1; d <= N; ++d) {
      if (def[d] < 0) throw ModelError(cs.where, "system DOF " + std::to_string(d) + " is unused");
      dofs.push_back(cand.list[def[d]]);
    }
    for (std::size_t e = 0; e < m.elements.size(); ++e) m.elements[e].table_row = cs.rows[e];
    return dofs;
  }

  // The table's shape (a row per element, 6 entries per node) and its largest DOF number.
  int table_size(const CorrelationSpec& cs) const {
    if (cs.rows.size() != m.elements.size())
      throw ModelError(cs.where, "has " + std::to_string(cs.rows.size()) + " rows, expected " +
                                     std::to_string(m.elements.size()) + " (one per element)");
    int N = 0;
    std::size_t entries = 0;
    for (const auto& row : cs.rows) entries += row.size();
    for (std::size_t e = 0; e < cs.rows.size(); ++e) {
      const std::string where = cs.where + "/" + std::to_string(e);
      if (cs.rows[e].size() != all_cand[e].size())
        throw ModelError(where, "has " + std::to_string(cs.rows[e].size()) + " entries, expected " +
                                    std::to_string(all_cand[e].size()) + " (6 per element node)");
      for (int d : cs.rows[e]) {
        if (d < 0) throw ModelError(where, "negative system DOF number");
        // Numbered 1, 2, … without gaps: no number exceeds the entries (nor sizes a huge buffer).
        if (static_cast<std::size_t>(d) > entries)
          throw ModelError(where,
                           "system DOF number " + std::to_string(d) + " exceeds the " +
                               std::to_string(entries) +
                               " entries of the table (DOFs are numbered 1, 2, … without gaps)");
        N = std::max(N, d);
      }
    }
    return N;
  }

  // Entry l of element e's row: 0 leaves its candidate out; a number names the candidate it
  // was first given to, and joins another only if both move alike (or, with join_deepest, takes
  // the deeper one's motion, an approximation).
  void define_by_table(const CorrelationSpec& cs, std::size_t e, std::size_t l,
                       std::vector<int>& def, std::vector<std::pair<int, std::string>>& joined) {
    const int d = cs.rows[e][l], c = all_cand[e][l];
    if (d == 0) {
      const std::string note =
          m.dof_name_of(cand.list[c]) + " (left out by the table although it moves)";
      if (local_cand[e][l] >= 0 && moves(Ts, c, tol) &&
          std::find(m.left_out.begin(), m.left_out.end(), note) == m.left_out.end())
        m.left_out.push_back(note);
      return;
    }
    if (def[d] < 0) {
      def[d] = c;
      return;
    }
    if (def[d] == c || same_motion(Ts, def[d], c, tol)) return;
    const std::string joins = "system DOF " + std::to_string(d) + " joins " +
                              m.dof_name_of(cand.list[def[d]]) + " and " +
                              m.dof_name_of(cand.list[c]) + ", which move differently";
    if (!cs.join_deepest)
      throw ModelError(cs.where + "/" + std::to_string(e) + "/" + std::to_string(l), joins);
    if (depth(m, carrier_body(m, cand.list[c])) > depth(m, carrier_body(m, cand.list[def[d]])))
      def[d] = c;
    joined.emplace_back(d, joins);
  }

  // A table that leaves out a moving DOF a load pushes on would drop the load silently.
  void check_loads_kept() const {
    for (const LoadAt& l : loads)
      for (int k = 0; k < 3; ++k) {
        const auto check = [&](DofKind kind, int carrier, int dof, double push) {
          const int c = cand.index.at(std::make_tuple(static_cast<int>(kind), carrier, k));
          if (push != 0 && dof < 0 && moves(Ts, c, tol))
            throw ModelError(l.where, "the load pushes on " + m.dof_name_of(cand.list[c]) +
                                          ", which the correlation table leaves out");
        };
        if (l.force[k] != 0) check(DofKind::Translation, l.node, m.node_dof[l.node][k], l.force[k]);
        if (!l.torque.isZero(0)) check(DofKind::Rotation, l.body, m.body_rot_dof[l.body][k], 1.0);
      }
  }

  // Assembly: M = Σ_e scatter(m_e) through N_m.
  void assemble_mass() {
    const int N = m.n_u();
    std::vector<Eigen::Triplet<double>> trip;
    for (const ElementEntry& e : m.elements) {
      const MatX me = e.element->local_mass();
      const auto& row = e.table_row;
      for (std::size_t l = 0; l < row.size(); ++l)
        for (std::size_t k = 0; k < row.size(); ++k)
          if (row[l] && row[k] && me(l, k) != 0)
            trip.emplace_back(row[l] - 1, row[k] - 1, me(l, k));
      if (e.element->has_velocity_force()) m.has_velocity_forces = true;
    }
    m.M.resize(N, N);
    m.M.setFromTriplets(trip.begin(), trip.end());
    m.M.makeCompressed();
  }

  // F = M·G (gravity: every translation accelerates by g) + point loads.
  void constant_forces() {
    const int N = m.n_u();
    VecX G = VecX::Zero(N);
    for (int i = 0; i < N; ++i)
      if (m.dofs[i].kind == DofKind::Translation) G[i] = m.gravity[m.dofs[i].axis];
    m.F_constant = m.M * G;
    for (const LoadAt& l : loads) {
      for (int k = 0; k < 3; ++k)
        if (m.node_dof[l.node][k] >= 0) m.F_constant[m.node_dof[l.node][k]] += l.force[k];
      if (!l.torque.isZero(0)) m.torques.push_back({l.body, l.torque});
    }
    m.has_nodal_forces = !m.torques.empty() || (N > 0 && m.F_constant.cwiseAbs().maxCoeff() > 0);
  }
};

}  // namespace

std::vector<VecX> sample_states(const Model& m, int count) {
  std::mt19937 rng(20261122u);
  std::uniform_real_distribution<double> uni(-2.0, 2.0);
  std::vector<VecX> qs;
  for (int s = 0; s < count; ++s) {
    VecX xi(m.n());
    for (int a = 0; a < m.n(); ++a) xi[a] = uni(rng);
    qs.push_back(integrate_posture(m, neutral_posture(m), xi));  // (q = ξ when flat)
  }
  return qs;
}

void build_node_level(MechanismSpec& spec, const std::vector<int>& body_of_spec, Model& m) {
  NodeLevel(spec, m).build(body_of_spec);
}

std::optional<MassMatrixProblem> mass_matrix_problem(const Model& m, bool list_inert) {
  if (m.n() == 0) return std::nullopt;
  Workspace ws(m);
  std::vector<VecX> states = sample_states(m, 2);
  states.insert(states.begin(), neutral_posture(m));
  const VecX rest = VecX::Zero(m.n());
  for (const VecX& q : states) {
    // The model's own route: the articulated recursion checks its pivots in O(bodies); the
    // Cholesky route factorises M^s.
    Status st;
    if (m.dynamics_route == DynamicsRoute::Articulated) {
      st = tree_forward_dynamics(m, ws, q, rest, rest);
    } else {
      evaluate(m, ws, q, rest, VecX());
      st = ws.solver.factorize(ws.Ms);
    }
    if (st.ok) continue;
    MassMatrixProblem p{m.where, st.message, {}};
    if (st.coordinate >= 0)
      for (const Body& b : m.bodies)
        if (b.joint.name == m.coordinate_names[st.coordinate]) p.where = b.joint.where;
    if (!list_inert || m.n() > 4000) return p;
    evaluate(m, ws, q, rest, VecX());  // (the articulated route formed no M^s)
    const double scale = ws.Ms.diagonal().cwiseAbs().maxCoeff();
    for (int a = 0; a < m.n(); ++a)
      if (!(ws.Ms(a, a) > 1e-13 * scale)) p.inert.push_back(m.coordinate_names[a]);
    return p;
  }
  return std::nullopt;
}

void check_mass_matrix(const Model& m) {
  if (const auto p = mass_matrix_problem(m)) throw ModelError(p->where, p->message);
}

}  // namespace femdyn
