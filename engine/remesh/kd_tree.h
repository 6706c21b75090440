#pragma once
/// \file kd_tree.h
/// nanoflann's view of a vector of points, and the kd-tree over it that the reference surface
/// (reference_surface.cpp) and the point index (point_index.cpp) build. Only .cpp files include
/// this header, so nanoflann stays out of the engine's interface.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <nanoflann.hpp>

#include "core/mesh.h"

namespace remesh {

struct PointCloud {
  const std::vector<Vec3>* points = nullptr;
  std::size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(std::uint32_t i, std::size_t dim) const { return (*points)[i][dim]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

/// Squared Euclidean distances (nanoflann 1.4.3: knnSearch and radiusSearch take and return them).
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloud>, PointCloud, 3,
                                                   std::uint32_t>;

/// Leaf size of the trees (nanoflann's default is 10).
constexpr std::size_t kKdTreeLeafSize = 16;

}  // namespace remesh
