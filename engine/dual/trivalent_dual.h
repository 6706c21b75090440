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

/// On an open mesh a triangle whose three corners are all boundary vertices gives a dual vertex in
/// no face; it is kept, so V* = F always holds (the XYZ atom list has one atom per triangle).
/// The dual edges are the primal edges with at least one interior end vertex.
///
/// \pre `primal` is a valid, consistently oriented 2-manifold TriMesh (as read_mesh returns). A
///      mesh with deleted elements is compacted first (on a copy); indices then refer to the copy.
/// \param reference when not null, each centroid goes to reference->closest_point(centroid,
///      triangle normal) (needs the remesher's library, remesh_equalize, linked).
/// \throw MeshError if a dual face cannot be added (the primal was not a valid oriented manifold).
PolyMesh trivalent_dual(const TriMesh& primal, const ReferenceSurface* reference = nullptr);

}  // namespace remesh
