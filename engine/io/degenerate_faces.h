#pragma once
/// \file degenerate_faces.h
/// Internal: zero-area triangles, and their repair on the half-edge mesh without changing its
/// topology (build_mesh.cpp).

#include <cstddef>
#include <vector>

#include "core/mesh.h"

namespace remesh::io {

/// True if triangle (a, b, c) has no area within double rounding: twice its area <= 1e-12 x its
/// longest edge squared, measured on its edges scaled by their largest component (no overflow or
/// underflow at any size, and no rounding of its distance from the origin). Coincident points
/// count as zero area.
bool zero_area(const Vec3& a, const Vec3& b, const Vec3& c);

/// What repair_zero_area_faces() did.
struct ZeroAreaRepair {
  /// Needles' short edges collapsed (the 1 or 2 faces on each went with it).
  std::size_t collapses = 0;
  /// Edges flipped under caps.
  std::size_t flips = 0;
  /// Faces deleted whose longest edge was on the boundary.
  std::size_t boundary_deletions = 0;
  /// Zero-area faces none of these repairs, still in the mesh.
  std::vector<OpenMesh::FaceHandle> left;
};

/// Removes zero-area faces from `mesh` keeping its topology (Euler characteristic, boundary loops,
/// components), starting from `faces` (distinct vertices each):
///
///   queue = faces
///   for each face f in queue that is still there and of zero area:
///     if f is a needle (shortest edge squared <= 1e-12 x longest squared, the bound the area
///       test puts on twice the area: its ends within 1e-6 of the face's size): collapse that
///       edge if is_collapse_ok (the boundary end stays, else the one of lower index, in place)
///     else f is a cap, its third point on its longest edge e: if e is interior, flip e if
///       is_flip_ok (the two new faces are the neighbour across e split at that point)
///     if neither and e is on the boundary: delete f unless that pinches a vertex or leaves its
///       component empty (the boundary then runs through the third point)
///     queue the zero-area faces the operation made; keep f aside if nothing applied
///   repeat with the faces kept aside while an operation succeeds (at most 8 per face + 64)
///
/// Leaves deleted elements (no garbage collection, so face handles stay valid) and stale normals.
/// \pre `mesh` is a valid 2-manifold triangle mesh with status attributes.
ZeroAreaRepair repair_zero_area_faces(TriMesh& mesh,
                                      const std::vector<OpenMesh::FaceHandle>& faces);

}  // namespace remesh::io
