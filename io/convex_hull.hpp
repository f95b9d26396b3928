// The convex hull of a point cloud as a closed triangle mesh (by Qhull, the library MuJoCo's
// compiler uses for the same): what MuJoCo weighs for a mesh given by vertices alone, or with
// inertia="convex".
#pragma once
#include <string>
#include <vector>

#include "io/mesh.hpp"

namespace femdyn {

// The hull's triangles, counter-clockwise seen from outside, over the points it keeps. Throws
// femdyn::Error ("<what>: …") when the points bound no volume: fewer than 4, or all on a plane.
TriangleMesh convex_hull(const std::vector<Vec3>& points, const std::string& what);

}  // namespace femdyn
