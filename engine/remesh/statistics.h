#pragma once
/// \file statistics.h
/// The statistics row (the thesis' table columns plus the fraction inside the interval) and the
/// parallel edge-length pass the other steps share. Reductions are done per fixed block and combined
/// in block order, so the numbers do not depend on the thread count.

#include <vector>

#include "core/mesh.h"
#include "remesh/equalize.h"

namespace remesh {

/// Length of every edge, by edge index (0 for deleted edges). Parallel.
std::vector<double> edge_lengths(const TriMesh& mesh, unsigned threads);

/// Mean length of the live edges (0 for none). Deterministic whatever the thread count.
double mean_edge_length(const TriMesh& mesh, unsigned threads);

/// Total area of the live faces.
double surface_area(const TriMesh& mesh);

// measure() is declared in equalize.h.

}  // namespace remesh
