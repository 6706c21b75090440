#pragma once
/// \file mesh_snapshot.h
/// A compact copy of a mesh to return to later (the polished mesh with the most regular vertices, a
/// stalled run's mesh with the fewest edges outside): its points and triangles only, about a fifth
/// of the memory of a TriMesh copy (which also holds halfedges, normals and status flags).

#include <array>
#include <cstdint>
#include <vector>

#include "core/mesh.h"

namespace remesh {

class MeshSnapshot {
 public:
  explicit MeshSnapshot(const TriMesh& mesh);

  /// The mesh again, built into `mesh` (whose own elements are freed first: a run's peak holds one
  /// mesh, not two): its live vertices in their order (renumbered past deleted ones) and its faces
  /// in their order, corners as they were.
  void rebuild(TriMesh& mesh) const;

 private:
  std::vector<Vec3> points_;
  std::vector<std::array<std::uint32_t, 3>> faces_;
};

}  // namespace remesh
