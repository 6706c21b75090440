#pragma once
/// \file triangle_bvh.h
/// Not in the thesis: the exact distance from a point to a triangle mesh, for measuring how far a
/// result lies from its input (surface_distance.h; the benchmark's Hausdorff distance): a
/// bounding-volume hierarchy (axis-aligned boxes, median splits) over the triangles. The
/// ReferenceSurface answers from the triangles around the 30 nearest vertices (the thesis'
/// Algorithm 6), which overestimates the distance where a mesh has long triangles next to dense
/// ones (nefertiti's base: triangles 20 long beside a rim of short ones): good for projecting,
/// not for measuring.

#include <cstdint>
#include <vector>

#include "core/mesh.h"

namespace remesh {

class TriangleBvh {
 public:
  explicit TriangleBvh(const TriMesh& mesh);

  /// Distance from p to the nearest point of the mesh's triangles (infinity without triangles).
  double distance(const Vec3& p) const;

 private:
  struct Triangle {
    Vec3 a, b, c;
  };
  struct Node {
    Vec3 lo, hi;
    std::uint32_t first = 0, count = 0;  ///< leaf: triangles [first, first + count); inner: count 0
    std::uint32_t right = 0;             ///< inner: the right child (the left one follows the node)
  };
  std::uint32_t build(std::uint32_t first, std::uint32_t count, std::vector<Vec3>& centroids);

  std::vector<Triangle> triangles_;
  std::vector<Node> nodes_;
};

}  // namespace remesh
