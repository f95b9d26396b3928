// A rigid body's mass properties as a file gives them, and the two operations a reader needs
// before it hands a body to the equations: merging the links welded together (one rigid body)
// and, on request, the nearest physical inertia to one that is not.
#pragma once
#include <string>

#include "core/spatial/math.hpp"

namespace femdyn {

// Mass m, centre of mass c and inertia I about c, all in one frame.
struct CentroidalMass {
  double mass = 0;
  Vec3 com = Vec3::Zero();
  Mat3 inertia = Mat3::Zero();

  bool empty() const { return mass == 0 && inertia.cwiseAbs().maxCoeff() == 0; }
  // The same body seen from a frame in which this one's frame sits at (R, p): x ↦ R x + p.
  CentroidalMass expressed_in(const Mat3& R, const Vec3& p) const;
};

// Two bodies welded into one (both in the same frame): m = m₁ + m₂, c = (m₁c₁ + m₂c₂)/m,
// I = Σ Iₖ + mₖ(|dₖ|² 1 − dₖdₖᵀ), dₖ = cₖ − c (parallel axes). Massless parts add their I.
CentroidalMass welded(const CentroidalMass& a, const CentroidalMass& b);

// The physical inertia nearest to I in second moments: Σ = ½ tr(I) 1 − I is the body's
// second-moment tensor ∫ r rᵀ dm about c, physical exactly when Σ ⪰ 0 (then I = tr(Σ) 1 − Σ has
// principal moments ≥ 0 that satisfy the triangle inequality). Σ's negative eigenvalues are set
// to 0 (the Frobenius-nearest Σ ⪰ 0) and I rebuilt. A physical I comes back unchanged.
Mat3 nearest_physical_inertia(const Mat3& I);

// "a, b, c": I's principal moments, ascending, for reports.
std::string principal_moments_text(const Mat3& I);

}  // namespace femdyn
