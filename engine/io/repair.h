#pragma once
/// \file repair.h
/// Internal: the triangle soup between the reader's polygons and the TriMesh, and the repair
/// steps that work on it (build_mesh.cpp, topology.cpp, triangulate.cpp).

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
};

/// Appends triangles covering the simple polygon idx[0..n) (n >= 3): ear clipping in the plane of
/// the polygon's Newell normal, falling back to a fan when the polygon is degenerate, self-
/// intersecting or has more than 256 corners. Indices must be valid.
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

/// Splits vertices whose faces form several fans (pinched vertices), one copy per extra fan.
/// `uses` comes from check_edges_and_orient(). Appends "nonmanifold_vertices_split".
void split_pinched_vertices(TriSoup& soup, const std::vector<EdgeUse>& uses, std::vector<Repair>& repairs);

}  // namespace remesh::io
