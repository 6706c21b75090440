#pragma once
/// \file reposition.h
/// Eq. 3.1: the vertex created by a split or kept by a collapse is placed on the segment [a, b] of
/// the original edge, at the t in [0, 1] that minimises
///     E(t) = sum_j (|a + t (b - a) - V_j| - m_i)^2
/// over its neighbours V_j after the operation. E is not always unimodal, so t is first bracketed by
/// sampling, then refined by golden-section search.

#include <vector>

#include "core/mesh.h"

namespace remesh {

/// E(t) of eq. 3.1.
double equalization_energy(const Vec3& a, const Vec3& b, double t, const std::vector<Vec3>& neighbours,
                           double target);

/// The minimiser t in [0, 1] of eq. 3.1 (to about 1e-6). With no neighbours, 0.5.
double equalizing_parameter(const Vec3& a, const Vec3& b, const std::vector<Vec3>& neighbours, double target);

/// Neighbours of the vertex that splits edge e: its two ends and the opposite vertices.
std::vector<Vec3> split_neighbours(const TriMesh& mesh, OpenMesh::EdgeHandle e);

/// Neighbours of the vertex that a collapse of halfedge h leaves: the union of the one-rings of both
/// ends, without the ends themselves.
std::vector<Vec3> collapse_neighbours(const TriMesh& mesh, OpenMesh::HalfedgeHandle h);

}  // namespace remesh
