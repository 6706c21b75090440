#include "remesh/crease_lines.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "remesh/geometry.h"

namespace remesh {

namespace {

/// The median length of the edges (0 with none).
double median_length(const TriMesh& mesh, const std::vector<OpenMesh::EdgeHandle>& edges) {
  std::vector<double> lengths;
  for (auto e : edges) lengths.push_back(mesh.calc_edge_length(e));
  if (lengths.empty()) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<long>(lengths.size() / 2), lengths.end());
  return lengths[lengths.size() / 2];
}

std::uint32_t root(std::vector<std::uint32_t>& parent, std::uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

/// The edges sharper than kCreaseAngle, in connected groups of at least kMinCreaseEdges.
std::vector<OpenMesh::EdgeHandle> crease_edges(const TriMesh& mesh) {
  const double limit = std::cos(kCreaseAngle);
  std::vector<OpenMesh::EdgeHandle> sharp;
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted() || mesh.is_boundary(e)) continue;
    const Vec3 a = geom::face_normal(mesh, mesh.face_handle(mesh.halfedge_handle(e, 0)));
    const Vec3 b = geom::face_normal(mesh, mesh.face_handle(mesh.halfedge_handle(e, 1)));
    const double na = a.norm(), nb = b.norm();
    if (na > 0 && nb > 0 && (a | b) < limit * na * nb) sharp.push_back(e);
  }
  std::vector<std::uint32_t> parent(mesh.n_vertices());
  std::iota(parent.begin(), parent.end(), 0u);
  auto ends = [&](OpenMesh::EdgeHandle e) {
    const auto h = mesh.halfedge_handle(e, 0);
    return std::pair{static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx()),
                     static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx())};
  };
  for (auto e : sharp) {
    const auto [a, b] = ends(e);
    parent[root(parent, a)] = root(parent, b);
  }
  std::vector<std::uint32_t> count(mesh.n_vertices(), 0);
  for (auto e : sharp) ++count[root(parent, ends(e).first)];
  std::vector<OpenMesh::EdgeHandle> out;
  for (auto e : sharp)
    if (count[root(parent, ends(e).first)] >= kMinCreaseEdges) out.push_back(e);
  return out;
}

}  // namespace

CreaseLines::CreaseLines(const TriMesh& reference) : CreaseLines(reference, crease_edges(reference)) {}

CreaseLines::CreaseLines(const TriMesh& reference, const std::vector<OpenMesh::EdgeHandle>& edges)
    : samples_(std::vector<Vec3>{}) {
  points_.assign(reference.n_vertices(), Vec3(0, 0, 0));
  for (auto v : reference.vertices()) points_[v.idx()] = reference.point(v);
  std::vector<std::vector<std::uint32_t>> at(points_.size());  // the segments at each point
  for (auto e : edges) {
    const auto h = reference.halfedge_handle(e, 0);
    const auto a = static_cast<std::uint32_t>(reference.from_vertex_handle(h).idx());
    const auto b = static_cast<std::uint32_t>(reference.to_vertex_handle(h).idx());
    at[a].push_back(static_cast<std::uint32_t>(segments_.size()));
    at[b].push_back(static_cast<std::uint32_t>(segments_.size()));
    segments_.push_back({a, b});
  }
  // Points along each segment at most `step` apart (the median segment's length): a point within
  // tol of a segment is within step / 2 + tol of one of its samples, so a query looks at a few
  // samples even where some creases are hundreds of times longer than the rest (cheese).
  const double step = median_length(reference, edges);
  std::vector<Vec3> samples;
  for (std::uint32_t s = 0; s < segments_.size(); ++s) {
    const Vec3 &a = points_[segments_[s].a], &b = points_[segments_[s].b];
    const auto pieces = static_cast<std::size_t>(std::ceil((b - a).norm() / step));
    for (std::size_t k = 0; k <= std::max<std::size_t>(pieces, 1); ++k) {
      samples.push_back(a + (b - a) * (static_cast<double>(k) / static_cast<double>(std::max<std::size_t>(pieces, 1))));
      sample_segment_.push_back(s);
    }
  }
  reach_ = 0.5 * step;
  samples_ = PointIndex(std::move(samples));
  corner_.assign(points_.size(), 0);
  through_.assign(points_.size(), Vec3(0, 0, 0));
  for (std::uint32_t p = 0; p < points_.size(); ++p) {
    if (at[p].empty()) continue;
    if (at[p].size() != 2) {
      corner_[p] = 1;
      continue;
    }
    auto other = [&](std::uint32_t s) { return segments_[s].a == p ? segments_[s].b : segments_[s].a; };
    const Vec3 in = (points_[p] - points_[other(at[p][0])]).normalized();
    const Vec3 out = (points_[other(at[p][1])] - points_[p]).normalized();
    if ((in | out) < std::cos(kCreaseBend)) corner_[p] = 1;
    else through_[p] = (in + out).normalized();
  }
}

CreaseLines::Where CreaseLines::locate(const Vec3& p, double tol) const {
  Where where;
  if (segments_.empty()) return where;
  thread_local std::vector<std::uint32_t> near;
  samples_.within(p, reach_ + tol * 2, near);
  for (std::uint32_t sample : near) {
    const std::uint32_t s = sample_segment_[sample];
    const Vec3 &a = points_[segments_[s].a], &b = points_[segments_[s].b];
    if ((geom::closest_point_on_segment(p, a, b) - p).sqrnorm() > tol * tol) continue;
    // At an end: that point's kind decides.
    for (std::uint32_t end : {segments_[s].a, segments_[s].b})
      if ((points_[end] - p).sqrnorm() <= tol * tol) {
        if (corner_[end]) return {Kind::Corner, Vec3(0, 0, 0)};
        return {Kind::Line, through_[end]};
      }
    where = {Kind::Line, (b - a).normalized()};
  }
  return where;
}

}  // namespace remesh
