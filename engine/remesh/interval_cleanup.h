#pragma once
/// \file interval_cleanup.h
/// Not in the thesis: its conclusion asks for a post-process that removes the last edges outside
/// [e_min, e_max]; this is it. It runs after the last iteration (Params::cleanup). For each edge
/// still outside the interval, worst first, it tries in order the local fixes below and keeps the
/// first that is safe (no fold, no degenerate triangle, no topology change: the same checks as the
/// stellar operations) and strictly lowers the number of edges outside the interval around it:
///   1. flip a long or short interior edge whose other diagonal lies inside the interval (the four
///      edges around it do not change);
///   2. collapse a short edge, the kept vertex placed by eq. 3.1 and projected onto the reference,
///      if every edge it ends up with lies inside the interval;
///   3. split a long edge, the new vertex placed by eq. 3.1 and projected, if its four (three on the
///      boundary) edges lie inside;
///   4. relocate an interior end vertex within its tangent plane (a few gradient steps on the squared
///      distance of its edge lengths to the interval), project it, keep it if fewer of its edges
///      are outside and none of its faces folds.
/// Rounds repeat while they fix something (at most `rounds`). Every vertex it creates or moves lies
/// on the reference surface, so the Hausdorff distance does not grow; on a mesh whose edges are all
/// inside it does nothing (idempotent).

#include <cstddef>
#include <utility>
#include <vector>

#include "core/mesh.h"
#include "remesh/reference_surface.h"

namespace remesh {

struct CleanupCounts {
  std::size_t flips = 0, collapses = 0, splits = 0, relocations = 0, patches = 0;
  std::size_t outside_before = 0, outside_after = 0;  ///< edges outside [e_min, e_max]
};

/// Runs the cleanup. Precondition: no deleted elements (garbage-collected); it leaves the mesh
/// garbage-collected too. `flip_factor` is Params::flip_factor.
/// With `boundary_only`, only edges with an end on the boundary are treated (see equalize.cpp: on
/// open meshes this runs every iteration, because boundary vertices never move in the filter and
/// split/collapse alone cannot even out a boundary whose edges are, say, 1.1 m long).
CleanupCounts interval_cleanup(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                               double flip_factor, int rounds = 4, bool boundary_only = false);

/// Moves each listed vertex onto its target point (a point of the reference) and relaxes the
/// interior vertices within 2 rings of it around the pinned vertex, as the patch relaxation does;
/// keeps a move only if it folds nothing and leaves no more edges of the patch outside
/// [e_min, e_max] than before. Returns the number of moves kept. Used by feature_snap.h.
std::size_t snap_to_features(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                             const std::vector<std::pair<OpenMesh::VertexHandle, Vec3>>& moves);

}  // namespace remesh
