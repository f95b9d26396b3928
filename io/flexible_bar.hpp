// A flexible bar (docs/flexible.md): a 3-D beam clamped to a body, kept elastic by the rigid
// finite element method. The bar of length L is cut into n parts of length Δ = L/n; a
// spring-damper joint sits at the middle of each part, x_i = (i − ½)Δ (i = 1 … n), and the rigid
// pieces between them are the bar's own mass and rotary inertia: a piece of Δ/2 at the clamp
// (fixed to the parent), n − 1 pieces of Δ, a piece of Δ/2 at the tip. Joint i turns about the
// piece's x (torsion, stiffness GJ/Δ), y and z (bending, EI_y/Δ and EI_z/Δ), then slides along
// the turned x (axial stretch, EA/Δ): each a one-rate joint with its spring, so that every route,
// derivative and the Simbody twin apply as they are. The elastic coordinates are
// "<bar>.<i>.ux", ".rx", ".ry", ".rz"; the pieces are bodies "<bar>.0" … "<bar>.<n>" and the
// bar's far end is the massless body "<bar>.tip" (its frame at the end, the bar's axes). A curved
// bar ("curvature") rests on an arc: its joints on it, its pieces the chords between them, each
// body's frame along the arc's tangent.
#pragma once
#include "compile/spec.hpp"
#include "io/params.hpp"

namespace femdyn {

// The bar described by p ({"name", "parent", "origin", "length", "segments", "section", "axial",
// "torsion", "damping", "curvature"}, docs/model-format.md#flexible-bars): its bodies as JSON
// bodies of the model format, and its centreline (the stations "<bar>.0" … "<bar>.<n>",
// "<bar>.tip"). Every number is checked here, with p's paths.
struct FlexibleBarParts {
  Json bodies;
  BarSpec centreline;
};
FlexibleBarParts flexible_bar_parts(const Params& p);

}  // namespace femdyn
