#pragma once
/// \file fold_guard.h
/// Not in the thesis: the safety net of the vertex-moving phases (filter, projection): after they
/// ran, any triangle that folded over (its normal turned by more than 90 degrees), folded onto a
/// neighbour (geom::adjacent_ok) or became degenerate (a smallest angle under geom::kMinAngle it did
/// not have before) gets its vertices put back where they were before the phases, repeatedly until
/// no such triangle is left. A vertex put back loses both moves, the filter's and the projection's.
/// Since the positions before the phases were valid, this always terminates with a valid mesh.

#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "remesh/reference_surface.h"

namespace remesh {

/// Current positions of all vertices, by index.
std::vector<Vec3> snapshot_points(const TriMesh& mesh);

/// Restores vertices of folded or degenerate faces to `before` (positions by vertex index, of the
/// same connectivity). Returns how many vertices were restored.
std::size_t undo_folds(TriMesh& mesh, const std::vector<Vec3>& before, unsigned threads);

/// Not in the thesis: the same net for the interval, used once the interval cleanup has taken over
/// (equalize.cpp, kSteadyAfter). Every edge that was inside [e_min, e_max] at `before` and is not
/// now gets both ends moved half way back to `before` (`halvings` times at most, then all the way),
/// repeatedly until no such edge is left. Returns the number of moves back. With `reference`, each
/// vertex left part of the way back is then projected onto it (project_vertex, through its kd-tree
/// answer in `caches`, by vertex index, when given), and goes all the way back if that takes an edge
/// out of the interval: between two points of a curved surface the midpoint lies under it (a
/// cylinder of radius 1 at [0.08, 0.12]: 16 vertices up to 7.8e-5 off its surface).
std::size_t undo_interval_breaks(TriMesh& mesh, const std::vector<Vec3>& before, double e_min, double e_max,
                                 int halvings = 3, const ReferenceSurface* reference = nullptr,
                                 std::vector<NeighbourCache>* caches = nullptr);

}  // namespace remesh
