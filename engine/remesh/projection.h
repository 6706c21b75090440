#pragma once
/// \file projection.h
/// Algorithm 6: move every vertex to the closest point of the reference surface (the triangles
/// incident to its 30 nearest reference vertices, found with the kd-tree of ReferenceSurface).
/// Not in the thesis: boundary vertices go to the closest point of the reference's boundary curves
/// (the boundary edges at their 30 nearest reference vertices), so boundaries stay boundaries.
/// Where two sheets are close, the candidate whose normal agrees with the vertex normal wins
/// (ALGORITHM.md: prefer it). Parallel over vertices; each vertex's result depends only on the
/// mesh before the step.

#include <vector>

#include "core/mesh.h"
#include "remesh/reference_surface.h"

namespace remesh {

/// Projects every live, non-isolated vertex of `mesh` onto `reference`. Returns the largest
/// distance a vertex moved (mesh units). With `caches`, interior vertex i keeps its kd-tree answer in
/// (*caches)[i] for the next call (resized as needed). The answer stays exact whichever vertex a
/// cache came from (reference_surface.h), so renumbering by garbage collection costs only misses.
double project_onto_reference(TriMesh& mesh, const ReferenceSurface& reference, unsigned threads,
                              std::vector<NeighbourCache>* caches = nullptr);

/// Projects the given vertices (live ones; the others are passed over) onto `reference`, each
/// only where the move folds nothing (geom::move_is_safe). The targets are found in parallel, each
/// from the mesh as it is on entry (so the result is the same whatever the thread count), then the
/// moves are checked and made one after the other, in the order given. With `caches` (indexed by
/// vertex, as project_onto_reference keeps them; not written), a vertex's search starts from the
/// cache at its index or, for a vertex without one (a split's), a neighbour's: after a garbage
/// collection a slot may hold another vertex's answer, exact all the same, only less often
/// reusable. Returns how many moved.
std::size_t project_vertices(TriMesh& mesh, const std::vector<OpenMesh::VertexHandle>& vertices,
                             const ReferenceSurface& reference, unsigned threads = 1,
                             const std::vector<NeighbourCache>* caches = nullptr);

/// The position one vertex would take: closest_boundary_point for boundary vertices, else
/// closest_point with `normal` as the hint (through `cache` when given).
Vec3 project_vertex(const TriMesh& mesh, OpenMesh::VertexHandle v, const Vec3& p, const Vec3& normal,
                    const ReferenceSurface& reference, NeighbourCache* cache = nullptr);

}  // namespace remesh
