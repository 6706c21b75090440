#pragma once
/// \file reference_surface.h
/// The reference surface of the projection step (Algorithm 6): a copy of a triangle mesh with a
/// nanoflann kd-tree over its vertices. closest_point() looks at the triangles incident to the 30
/// nearest reference vertices and returns the closest point on them; where candidates are nearly as
/// close (thin parts, two sheets), the one whose normal agrees with `normal_hint` wins.
/// Queries are const and safe from several threads.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "core/mesh.h"

namespace remesh {

class ReferenceSurface {
 public:
  explicit ReferenceSurface(const TriMesh& mesh, std::size_t neighbours = 30);
  ~ReferenceSurface();
  ReferenceSurface(ReferenceSurface&&) noexcept;
  ReferenceSurface& operator=(ReferenceSurface&&) noexcept;

  /// Closest point on the reference surface to `p`. `normal_hint` may be zero (no preference).
  Vec3 closest_point(const Vec3& p, const Vec3& normal_hint = Vec3(0, 0, 0)) const;

  /// Closest point to `p` on the boundary curves of the reference (the boundary edges incident to
  /// the nearest reference vertices). Falls back to closest_point(p) when none is near.
  Vec3 closest_boundary_point(const Vec3& p) const;

  /// Indices of the (at most k, at most 64) reference vertices nearest to p, nearest first. An index
  /// is the vertex's rank among the live vertices of the mesh it was built from, i.e. its idx() when
  /// that mesh had no deleted vertices.
  std::size_t nearest_vertices(const Vec3& p, std::size_t k, std::uint32_t* out) const;

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
