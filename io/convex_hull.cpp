#include "io/convex_hull.hpp"

#include <cstdio>
#include <memory>
#include <unordered_map>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include "core/model/errors.hpp"

namespace femdyn {
namespace {

// Qhull's state for one call, freed on every path out.
struct Hull {
  qhT qh;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> errors{std::fopen("/dev/null", "w"),
                                                         &std::fclose};
  Hull() { qh_zero(&qh, errors.get()); }
  ~Hull() {
    int long_count = 0, long_bytes = 0;
    qh_freeqhull(&qh, !qh_ALL);
    qh_memfreeshort(&qh, &long_count, &long_bytes);
  }
  Hull(const Hull&) = delete;
  Hull& operator=(const Hull&) = delete;
};

}  // namespace

TriangleMesh convex_hull(const std::vector<Vec3>& points, const std::string& what) {
  const auto refuse = [&](const std::string& why) {
    throw Error(what + ": its convex hull bounds no volume (" + why + ")");
  };
  if (points.size() < 4) refuse(std::to_string(points.size()) + " vertices; a solid needs 4");
  std::vector<coordT> xyz;
  xyz.reserve(3 * points.size());
  for (const Vec3& p : points) {
    if (!p.allFinite()) throw Error(what + ": a vertex is NaN or infinite");
    xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  }
  Hull h;
  // Qt: triangulated facets. Qhull refuses a flat or degenerate cloud with a non-zero code.
  char options[] = "qhull Qt";
  if (qh_new_qhull(&h.qh, 3, static_cast<int>(points.size()), xyz.data(), False, options, nullptr,
                   h.errors.get()) != 0)
    refuse("the vertices are all on one plane or line");
  qhT* qh = &h.qh;  // (Qhull's iteration macros name it `qh`)
  TriangleMesh out;
  std::unordered_map<int, std::uint32_t> kept;  // input index → out.vertices index
  const auto index_of = [&](const vertexT* v) {
    const int id = qh_pointid(qh, v->point);
    const auto [at, added] = kept.emplace(id, static_cast<std::uint32_t>(out.vertices.size()));
    if (added) out.vertices.push_back(points[id]);
    return at->second;
  };
  facetT* facet;
  vertexT *vertex, **vertexp;
  FORALLfacets {
    std::array<std::uint32_t, 3> t{};
    int k = 0;
    FOREACHvertex_(facet->vertices) if (k < 3) t[k++] = index_of(vertex);
    if (k != 3) refuse("Qhull returned a facet that is not a triangle");
    // Outward: the facet's normal is outward, so turn the triangle to agree with it.
    const Vec3 &a = out.vertices[t[0]], &b = out.vertices[t[1]], &c = out.vertices[t[2]];
    const Vec3 normal(facet->normal[0], facet->normal[1], facet->normal[2]);
    if ((b - a).cross(c - a).dot(normal) < 0) std::swap(t[1], t[2]);
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace femdyn
