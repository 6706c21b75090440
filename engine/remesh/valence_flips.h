#pragma once
/// \file valence_flips.h
/// Algorithm 4 as ../shared/ALGORITHM.md corrects it (the pseudocode's test is inverted; the prose
/// is right). For an interior edge V1V3 with opposite vertices V2, V4:
///   dev  = sum over the four of |valence - target| (target 6 inside, 4 on the boundary)
///   amin = smallest angle of the two triangles
/// The edge is flipped only if dev_after < dev_before, amin_after >= f * amin_before, the flip is
/// topologically legal (is_flip_ok, no vertex left with valence < 3) and folds no triangle (both new
/// normals agree with both old ones) nor creates a degenerate one. We test before flipping, which
/// is the same as flipping and undoing.

#include <cstddef>

#include "core/mesh.h"

namespace remesh {

/// Does edge e pass the valence-and-angle rule and the safety checks with factor f?
bool flip_improves(const TriMesh& mesh, OpenMesh::EdgeHandle e, double f);

/// One sweep over all edges in index order, flipping each edge that passes flip_improves().
/// Returns the number of flips.
std::size_t valence_flip_sweep(TriMesh& mesh, double f);

/// Sweeps while they still flip something, at most `max_sweeps` times (the thesis does one; more
/// sweeps raise regularity at little cost). Returns the total number of flips.
std::size_t valence_flips(TriMesh& mesh, double f, int max_sweeps = 3);

/// Safety part of a flip alone (legal, no fold, no degenerate triangle, minimum angle no lower than
/// f * before). Used by the interval cleanup too.
bool flip_is_safe(const TriMesh& mesh, OpenMesh::EdgeHandle e, double f);

}  // namespace remesh
