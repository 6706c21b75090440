#pragma once
/// \file point_index.h
/// A fixed set of points with a nanoflann kd-tree over them: which points lie within a radius of a
/// query point, and how far the nearest one is. The feature snap uses it for the reference vertices
/// a move is judged by (GapJudge in interval_cleanup.cpp) and for the points whose distance to the
/// mesh a pass of moves can have changed (feature_snap.cpp). Queries are const and safe from
/// several threads.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/mesh.h"

namespace remesh {

class PointIndex {
 public:
  explicit PointIndex(std::vector<Vec3> points);
  ~PointIndex();
  PointIndex(PointIndex&&) noexcept;
  PointIndex& operator=(PointIndex&&) noexcept;

  const std::vector<Vec3>& points() const;
  std::size_t size() const { return points().size(); }

  /// Indices of the points strictly closer than `radius` to p, in increasing order, into `out`
  /// (cleared first).
  void within(const Vec3& p, double radius, std::vector<std::uint32_t>& out) const;

  /// Distance from p to the nearest point; infinity when there is none.
  double nearest_distance(const Vec3& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace remesh
