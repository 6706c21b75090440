#pragma once
/// \file low_pass_filter.h
/// Algorithm 5: tangential k-ring low-pass filter. For every vertex V_i:
///   V'_i = sum_j V_j / r_j  /  sum_j 1 / r_j   over the vertices V_j of rings 1..k around V_i
///   (r_j = ring index of V_j), T_i = V'_i - V_i minus its component along the vertex normal N_i.
/// All T_i are computed from the same positions and applied afterwards (Jacobi). Boundary vertices
/// do not move; nor do corners (is_corner, not in the thesis). Not in the thesis either: given the
/// reference's creases (crease_lines.h), a vertex on a crease moves along it only (T_i's component
/// along the crease) and one at a corner of the creases not at all. Parallel over vertices.

#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"

namespace remesh {

/// Angle deficit |2 pi - sum of the angles around a vertex| above which it is a corner (a tip, a
/// sharp cone), radians. Not in the thesis: a smooth surface sampled at the target length has
/// deficits far below it.
constexpr double kCornerDeficit = 1.0;

/// Is v a corner: the apex of a sharp cone, or a saddle as sharp (|angle deficit| above
/// kCornerDeficit)? Not in the thesis: such vertices stay where they are in the filter, like
/// boundary vertices: moving a tip sideways and projecting it back
/// always lands lower on the cone, and over many iterations the tip wears away (the cow's horns
/// lost 4 edge lengths: Hausdorff 4.8 % of the bbox diagonal against CGAL's 0.9 %).
bool is_corner(const TriMesh& mesh, OpenMesh::VertexHandle v);

/// The tangential displacement T_i of every vertex (zero for boundary, isolated, deleted and
/// corner vertices).
/// `rings` in 1..4.
/// `creases` may be null (none); a vertex within `tol` of a crease lies on it.
std::vector<Vec3> low_pass_displacements(const TriMesh& mesh, int rings, unsigned threads,
                                         const CreaseLines* creases = nullptr, double tol = 0);

/// Computes and applies the displacements. Returns the largest displacement length.
double low_pass_filter(TriMesh& mesh, int rings, unsigned threads, const CreaseLines* creases = nullptr,
                       double tol = 0);

}  // namespace remesh
