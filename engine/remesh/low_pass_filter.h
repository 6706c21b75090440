#pragma once
/// \file low_pass_filter.h
/// Algorithm 5: tangential k-ring low-pass filter. For every vertex V_i:
///   V'_i = sum_j V_j / r_j  /  sum_j 1 / r_j   over the vertices V_j of rings 1..k around V_i
///   (r_j = ring index of V_j), T_i = V'_i - V_i minus its component along the vertex normal N_i.
/// All T_i are computed from the same positions and applied afterwards (Jacobi). Boundary vertices
/// do not move. Parallel over vertices.

#include <vector>

#include "core/mesh.h"

namespace remesh {

/// The tangential displacement T_i of every vertex (zero for boundary, isolated, deleted vertices).
/// `rings` in 1..4.
std::vector<Vec3> low_pass_displacements(const TriMesh& mesh, int rings, unsigned threads);

/// Computes and applies the displacements. Returns the largest displacement length.
double low_pass_filter(TriMesh& mesh, int rings, unsigned threads);

}  // namespace remesh
