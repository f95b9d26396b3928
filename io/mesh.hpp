// Triangle meshes from the files robot descriptions name (STL binary or ASCII, Wavefront OBJ):
// what a reader needs to take a body's mass from its mesh, and what `femdyn view` draws.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "io/centroidal_mass.hpp"

namespace femdyn {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside
};

// The mesh in `path`, by its extension (.stl, .obj; any case), each vertex scaled by `scale`
// component-wise. Errors are femdyn::Error naming the file and the line or byte: an unknown
// extension (Collada .dae included), a truncated or malformed file, an index out of range,
// a non-finite coordinate, no triangle.
TriangleMesh read_mesh(const std::string& path, const Vec3& scale = Vec3::Ones());

// The solid the closed, consistently wound mesh bounds, of uniform density ρ, in the mesh's
// frame: volume V = Σ_f det[a b c]/6 over the tetrahedra from a point o to each face (a, b, c
// from o; signed, so any closed mesh, convex or not, is exact; o the vertices' mean, so that
// the result does not depend on where the mesh sits), centre c = Σ V_f (a+b+c)/4 / V and inertia
// about c from the second moments ∫ r rᵀ dV = Σ V_f/20 (Σ_k v_k v_kᵀ + s sᵀ), s = a+b+c (Tonon
// 2004). Orientation-free: a mesh wound inside out (V < 0) is taken with its sign flipped. `volume`
// gets |V|. A mesh of no volume (open, flat) gives V = 0, which callers refuse.
CentroidalMass solid_mass(const TriangleMesh& mesh, double density, double* volume = nullptr);

}  // namespace femdyn
