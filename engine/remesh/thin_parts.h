#pragma once
/// \file thin_parts.h
/// Not in the thesis: why a run leaves edges outside [e_min, e_max]. A tube of the surface thinner
/// than 2 e_min / sqrt(3) cannot carry a ring of three vertices on the surface with edges of e_min
/// or more (the three would form a triangle of side e_min, whose circumscribed circle has that
/// diameter), so where the reference is that thin no mesh of it has every edge in the interval.
/// The thickness at an edge is the distance from its midpoint to the nearest reference triangle
/// facing the other way (ReferenceSurface::opposite_side_distance; the edge's direction is the sum
/// of its faces' unit normals). Measured on the Table 4.2 runs (bench/README.md): every edge cow's
/// and cheese's simplifications leave outside lies in such a part.

#include <cstddef>

#include "core/mesh.h"
#include "remesh/reference_surface.h"

namespace remesh {

struct ThinParts {
  std::size_t outside = 0;        ///< edges outside [e_min, e_max]
  std::size_t in_thin_parts = 0;  ///< of them, where the reference is thinner than `limit`
  double limit = 0;               ///< 2 e_min / sqrt(3)
};

/// Counts the edges of `mesh` outside [e_min, e_max] and those of them in thin parts of
/// `reference` (see the file comment), on up to `threads` threads.
ThinParts thin_parts(const TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                     unsigned threads = 1);

}  // namespace remesh
