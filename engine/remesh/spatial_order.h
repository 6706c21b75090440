#pragma once
/// \file spatial_order.h
/// Not in the thesis: the mesh's elements numbered in space order, so that neighbours lie near
/// each other in memory. Every step walks the mesh in index order (the flip sweeps, the filter, the
/// projection, the guards) and reads each element's neighbours; the splits of the stellar operations
/// append their new elements in the priority list's order (by length, all over the surface), and
/// garbage collection moves the last elements into the holes of the deleted ones, so after a few
/// iterations a neighbour is anywhere in memory. On a mesh larger than the processor's caches the
/// steps then wait on memory. When equalize() numbers the mesh, and what it gains: kOrderShare in
/// equalize.cpp (armadillo and nefertiti refined in 40 % less time).

#include <vector>

#include "core/mesh.h"

namespace remesh {

/// Numbers the vertices of `mesh` anew along a Morton (Z-order) curve through their positions, the
/// faces by their lowest new corner, and the edges in the order the faces first use them. The mesh
/// stays the same mesh: the same faces, each halfedge's direction, each vertex's first outgoing
/// halfedge (so every circulation starts and runs as before). Returns the new index of each vertex.
/// Precondition: no deleted elements (collect_garbage). The same result whatever `threads` (its
/// loops write each element once; the sorts are serial).
std::vector<unsigned> spatial_order(TriMesh& mesh, unsigned threads = 1);

}  // namespace remesh
