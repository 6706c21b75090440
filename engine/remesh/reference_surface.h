#pragma once
/// \file reference_surface.h
/// The reference surface of the projection step (Algorithm 6): a copy of a triangle mesh with a
/// nanoflann kd-tree over its vertices. closest_point() looks at the triangles incident to the 30
/// nearest reference vertices and returns the closest point on them; where candidates are nearly as
/// close (thin parts, two sheets), the one whose normal agrees with `normal_hint` wins.
/// Two additions to Alg. 6 for uneven and defective inputs (reference_surface.cpp says why): from
/// the winning triangle, the search walks across edges to nearly coplanar neighbours while that gets
/// closer (a large triangle none of whose corners is among the 30 nearest), and a triangle folded
/// back onto a larger neighbour (normals nearly opposite) is never a candidate.
/// Queries are const and safe from several threads.
///
/// A NeighbourCache lets a caller that queries again from a nearby point (every vertex, every
/// iteration) skip the kd-tree: the cache keeps the kCacheSize nearest vertices of the last query
/// point q and the distance R to the farthest of them. Every other reference vertex is at least R
/// from q, so at least R - |p - q| from a new point p; when the 30 cached vertices nearest to p are
/// all closer than that, they are exactly the 30 nearest vertices the kd-tree would return.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/mesh.h"

namespace remesh {

/// The last kd-tree answer for one query point (see the file comment). Zero-initialised = empty.
struct NeighbourCache {
  static constexpr std::size_t kCacheSize = 40;
  Vec3 query{0, 0, 0};
  double radius = 0;            ///< distance from query to the farthest cached vertex
  std::uint64_t surface = 0;    ///< id of the ReferenceSurface that filled it; 0 = empty
  std::uint32_t count = 0;
  std::uint32_t idx[kCacheSize] = {};
};

class ReferenceSurface {
 public:
  explicit ReferenceSurface(const TriMesh& mesh, std::size_t neighbours = 30);
  ~ReferenceSurface();
  ReferenceSurface(ReferenceSurface&&) noexcept;
  ReferenceSurface& operator=(ReferenceSurface&&) noexcept;

  /// Closest point on the reference surface to `p`. `normal_hint` may be zero (no preference).
  Vec3 closest_point(const Vec3& p, const Vec3& normal_hint = Vec3(0, 0, 0)) const;
  /// The same point, with the nearest vertices taken from `cache` when it is still exact (and the
  /// cache refilled from the kd-tree when it is not).
  Vec3 closest_point(const Vec3& p, const Vec3& normal_hint, NeighbourCache& cache) const;

  /// Closest point to `p` on the boundary curves of the reference (the boundary edges incident to
  /// the nearest reference vertices). Falls back to closest_point(p) when none is near.
  Vec3 closest_boundary_point(const Vec3& p) const;

  /// Indices of the (at most k, at most 64) reference vertices nearest to p, nearest first. An index
  /// is the vertex's rank among the live vertices of the mesh it was built from, i.e. its idx() when
  /// that mesh had no deleted vertices.
  std::size_t nearest_vertices(const Vec3& p, std::size_t k, std::uint32_t* out) const;

  /// Distance from p to the nearest reference triangle that faces against `normal` (a unit vector;
  /// the triangle's unit normal n with n . normal < -0.3): the other side of the part p lies on.
  /// Only triangles nearer than `limit` are looked at; infinity when there is none. The search
  /// visits at most 16 384 reference vertices and long triangles, nearest first roughly (the
  /// Table 4.2 inputs need under 2 000); on a reference whose long triangles span most of it, it
  /// stops there with the nearest found so far.
  double opposite_side_distance(const Vec3& p, const Vec3& normal, double limit) const;
  /// Whether opposite_side_distance(p, normal, limit) < limit: the same test, stopped at the
  /// first such triangle.
  bool opposite_side_within(const Vec3& p, const Vec3& normal, double limit) const;

  /// True when the reference has at least one boundary edge.
  bool has_boundary() const;

  /// Reference vertex and triangle counts.
  std::size_t n_vertices() const;
  std::size_t n_triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace remesh
