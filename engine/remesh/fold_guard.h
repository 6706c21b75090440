#pragma once
/// \file fold_guard.h
/// The safety net of the vertex-moving phases (filter, projection): after they ran, any triangle
/// that folded over (its normal turned by more than 90 degrees) or became degenerate gets its
/// vertices put back where they were before the phases, repeatedly until no such triangle is left.
/// Since the positions before the phases were valid, this always terminates with a valid mesh.

#include <cstddef>
#include <vector>

#include "core/mesh.h"

namespace remesh {

/// Current positions of all vertices, by index.
std::vector<Vec3> snapshot_points(const TriMesh& mesh);

/// Restores vertices of folded or degenerate faces to `before` (positions by vertex index, of the
/// same connectivity). Returns how many vertices were restored.
std::size_t undo_folds(TriMesh& mesh, const std::vector<Vec3>& before, unsigned threads);

}  // namespace remesh
