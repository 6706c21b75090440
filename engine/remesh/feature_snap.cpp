#include "remesh/feature_snap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"
#include "remesh/geometry.h"
#include "remesh/interval_cleanup.h"
#include "remesh/reference_surface.h"

namespace remesh {

namespace {

bool on_crease(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  for (auto h : mesh.voh_range(v)) {
    const auto f = mesh.face_handle(h), g = mesh.opposite_face_handle(h);
    if (!f.is_valid() || !g.is_valid()) continue;
    const Vec3 nf = geom::face_normal(mesh, f), ng = geom::face_normal(mesh, g);
    const double l = nf.norm() * ng.norm();
    if (l > 0 && (nf | ng) < kCreaseCos * l) return true;
  }
  return false;
}

}  // namespace

FeatureSnap::FeatureSnap(const TriMesh& reference) {
  for (auto v : reference.vertices()) {
    if (reference.status(v).deleted() || reference.is_isolated(v) || reference.is_boundary(v)) continue;
    if (std::abs(geom::angle_deficit(reference, v)) > kTipDeficit || on_crease(reference, v))
      points_.push_back(reference.point(v));
  }
}

std::size_t FeatureSnap::apply(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                               unsigned threads) const {
  if (points_.empty() || mesh.n_faces() == 0) return 0;
  const ReferenceSurface current(mesh);
  const double tolerance = 0.1 * e_min;
  std::vector<double> gap(points_.size());
  parallel_for(points_.size(), threads, [&](std::size_t i) {
    gap[i] = (current.closest_point(points_[i]) - points_[i]).norm();
  }, 256);
  // Only the points that decide the Hausdorff distance: at least half as far as the farthest.
  const double far = std::max(tolerance, 0.5 * *std::max_element(gap.begin(), gap.end()));
  std::vector<std::uint32_t> order;
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (gap[i] > far) order.push_back(static_cast<std::uint32_t>(i));
  std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return gap[a] > gap[b]; });
  // Each far feature point takes its nearest mesh vertex that no farther point took already.
  std::vector<char> taken(mesh.n_vertices(), 0);
  std::vector<std::pair<OpenMesh::VertexHandle, Vec3>> moves;
  for (std::uint32_t i : order) {
    std::uint32_t near[3];
    const std::size_t found = current.nearest_vertices(points_[i], 3, near);
    for (std::size_t k = 0; k < found; ++k) {
      if (taken[near[k]]) continue;
      taken[near[k]] = 1;
      moves.emplace_back(mesh.vertex_handle(near[k]), points_[i]);
      break;
    }
  }
  return snap_to_features(mesh, reference, e_min, e_max, moves);
}

}  // namespace remesh
