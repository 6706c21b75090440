#pragma once
/// Helpers of the remesher tests, computed independently of the engine's own statistics.

#include <cstddef>

#include "core/mesh.h"

namespace remesh::test {

/// Mean length of the mesh's edges (plain loop).
double plain_mean_edge(const TriMesh& mesh);

/// Scales about the origin so the mean edge length becomes `mean`.
void scale_mean_edge(TriMesh& mesh, double mean);

/// Fraction of edges with length in [lo, hi].
double plain_inside_fraction(const TriMesh& mesh, double lo, double hi);

/// Distance from p to the nearest triangle of the mesh, by brute force over every face.
double brute_distance(const TriMesh& mesh, const Vec3& p);

/// The largest distance from points along the 12 edges of the box of make_box(n) (every 0.05) to
/// `mesh` (brute_distance).
double box_edges_distance(const TriMesh& mesh, int n);

}  // namespace remesh::test
