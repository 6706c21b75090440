#pragma once
/// \file repair.h
/// Internal: the triangle soup between the reader's polygons and the TriMesh, and the repair
/// steps that work on it (build_mesh.cpp, topology.cpp, triangulate.cpp).

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "io/soup.h"

namespace remesh::io {

using Tri = std::array<std::uint32_t, 3>;

struct TriSoup {
  std::vector<Vec3> points;
  std::vector<Tri> tris;
  std::vector<std::uint32_t> source;  ///< input face each triangle came from (for messages)
  std::vector<bool> welded_away;      ///< points merged into an earlier one (empty: no welding)
  std::vector<bool> zero_area;        ///< per triangle: of zero area, kept to be repaired on the mesh

  /// Keeps the triangles t with keep[t] (and their source and zero_area), in order.
  void retain(const std::vector<bool>& keep);
};

/// Degenerate faces dropped, reported together as "degenerate_faces_removed" (input face numbers).
struct DroppedFaces {
  std::size_t repeated = 0;   ///< with a repeated vertex index: no surface
  std::size_t zero_area = 0;  ///< of zero area, which could not be kept or repaired
  std::uint32_t first_repeated = UINT32_MAX, first_zero_area = UINT32_MAX;
  std::size_t pinched = 0, unused = 0;  ///< vertices split, and dropped, after the zero-area ones went

  void add_zero_area(std::uint32_t source) {
    ++zero_area;
    first_zero_area = std::min(first_zero_area, source);
  }
};

/// Appends triangles covering the simple polygon idx[0..n) (n >= 3): ear clipping in the plane of
/// the polygon's Newell normal, falling back to a fan when the polygon is degenerate or
/// self-intersecting (or, past 256 corners, after 5e7 point-in-ear tests). Indices must be valid.
void triangulate_polygon(const std::vector<Vec3>& points, const std::int64_t* idx, std::size_t n,
                         std::vector<Tri>& out);

/// One face's use of an undirected edge; sorted, equal (lo, hi) are adjacent.
struct EdgeUse {
  std::uint32_t lo, hi;  ///< vertex indices, lo < hi
  std::uint32_t tri;
  bool operator<(const EdgeUse& o) const { return lo != o.lo ? lo < o.lo : hi != o.hi ? hi < o.hi : tri < o.tri; }
};

/// Refuses edges with more than two faces (MeshError with count and first edge), then orients
/// every component consistently (flipping the minority; MeshError for a non-orientable one).
/// `raw` names input faces for messages. Appends a "faces_reoriented" repair if any. Returns
/// the sorted edge uses (still valid after re-orientation, which keeps vertex sets).
std::vector<EdgeUse> check_edges_and_orient(TriSoup& soup, const RawSoup& raw, std::vector<Repair>& repairs);

/// Drops the zero-area triangles that share an edge with more than one other face: kept, they
/// would make that edge non-manifold and the input be refused, where without them it reads.
void drop_crowding_zero_area(TriSoup& soup, DroppedFaces& dropped);

/// Splits vertices whose faces form several fans (pinched vertices), one copy per extra fan.
/// `uses` comes from check_edges_and_orient(). Appends "nonmanifold_vertices_split".
void split_pinched_vertices(TriSoup& soup, const std::vector<EdgeUse>& uses, std::vector<Repair>& repairs);

}  // namespace remesh::io
