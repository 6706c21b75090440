#pragma once
/// \file trivalent_dual.h
/// The trivalent dual of a triangle mesh (ALGORITHM.md, "The trivalent dual"): one dual vertex per
/// triangle (its centroid, projected onto `reference` when given), one dual face per interior primal
/// vertex (its triangles' dual vertices in counter-clockwise order, so dual normals agree with the
/// primal's), one dual edge per interior primal edge. Boundary primal vertices give no face.
/// Dual vertex i corresponds to primal face i (after garbage collection).

#include "core/mesh.h"

namespace remesh {

class ReferenceSurface;

/// Precondition: a valid, consistently oriented TriMesh without deleted elements.
PolyMesh trivalent_dual(const TriMesh& primal, const ReferenceSurface* reference = nullptr);

}  // namespace remesh
