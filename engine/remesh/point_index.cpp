#include "remesh/point_index.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "remesh/kd_tree.h"

namespace remesh {

struct PointIndex::Impl {
  std::vector<Vec3> points;
  PointCloud cloud;
  std::unique_ptr<KdTree> tree;
};

PointIndex::PointIndex(std::vector<Vec3> points) : impl_(std::make_unique<Impl>()) {
  impl_->points = std::move(points);
  impl_->cloud.points = &impl_->points;
  if (!impl_->points.empty()) {
    impl_->tree = std::make_unique<KdTree>(3, impl_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(kKdTreeLeafSize));
    impl_->tree->buildIndex();
  }
}

PointIndex::~PointIndex() = default;
PointIndex::PointIndex(PointIndex&&) noexcept = default;
PointIndex& PointIndex::operator=(PointIndex&&) noexcept = default;

const std::vector<Vec3>& PointIndex::points() const { return impl_->points; }

void PointIndex::within(const Vec3& p, double radius, std::vector<std::uint32_t>& out) const {
  out.clear();
  if (!impl_->tree || !(radius > 0)) return;
  std::vector<std::pair<std::uint32_t, double>> found;
  const double q[3] = {p[0], p[1], p[2]};
  // nanoflann's radius is squared (L2_Simple_Adaptor) and its test strict, as ours.
  impl_->tree->radiusSearch(q, radius * radius, found, nanoflann::SearchParams(32, 0.0f, false));
  out.reserve(found.size());
  for (const auto& [i, d2] : found) out.push_back(i);
  std::sort(out.begin(), out.end());
}

double PointIndex::nearest_distance(const Vec3& p) const {
  if (!impl_->tree) return std::numeric_limits<double>::infinity();
  std::uint32_t i = 0;
  double d2 = 0;
  const double q[3] = {p[0], p[1], p[2]};
  impl_->tree->knnSearch(q, 1, &i, &d2);
  return std::sqrt(d2);
}

}  // namespace remesh
