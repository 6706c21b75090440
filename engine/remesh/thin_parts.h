#pragma once
/// \file thin_parts.h
/// Not in the thesis: why a run leaves edges outside [e_min, e_max]. A tube of the surface thinner
/// than 2 e_min / sqrt(3) cannot carry a ring of three vertices on the surface with edges of e_min
/// or more (the three would form a triangle of side e_min, whose circumscribed circle has that
/// diameter), so where the reference is that thin no mesh of it has every edge in the interval.
/// The thickness at an edge is the distance from its midpoint to the nearest reference triangle
/// facing the other way (ReferenceSurface::opposite_side_distance; the edge's direction is the sum
/// of its faces' unit normals). Measured on the Table 4.2 runs (bench/README.md, "Where the edges left outside
/// lie"): of the edges cow's and cheese's simplifications leave outside, all but 3 of 1 192 lie in such a part.

#include <cstddef>

#include "core/mesh.h"
#include "remesh/crease_lines.h"
#include "remesh/reference_surface.h"

namespace remesh {

struct ThinParts {
  std::size_t outside = 0;        ///< edges outside [e_min, e_max]
  std::size_t in_thin_parts = 0;  ///< of them, where the reference is thinner than `limit`
  double limit = 0;               ///< 2 e_min / sqrt(3)
  /// Of the edges outside, those with an end of irregular valence (not 6 inside, not 4 on the
  /// boundary). A pair of valence 5 and 7 strains the edges at its core by 10-15 % (bench/HISTORY.md:
  /// on spot at [1.35, 1.65], 30 % of the edges at an irregular vertex were outside, 0.6 % of those
  /// two or more rings away), so in a tight interval these are the edges left outside.
  std::size_t at_irregular = 0;
  /// Of the edges outside, those with an end on a crease that Params::keep_creases holds (0 without
  /// it): where creases or their corners lie closer together than e_min, or a crease between two
  /// corners fits no whole number of edges in the interval, the kept creases leave edges outside.
  std::size_t at_creases = 0;
  /// Interior vertices by the reference's thickness where they lie (the distance from the vertex
  /// to the nearest reference triangle facing the other way, along the vertex normal): thinner
  /// than `vertex_limit` = 2 e_max, or not, and how many of each have valence 6. A tube a few
  /// edges round changes the number of vertices around it wherever it widens or narrows, and each
  /// change is a 5-7 pair (a dislocation of the lattice): thin tapering parts (legs, horns, tails,
  /// walls) hold irregular vertices that no flip can remove. Measured (bench/README.md, "Where the
  /// irregular vertices lie"): where the input is at least 2 e_max thick, the Table 4.2 meshes are
  /// 89.1-90.1 % regular; cow's thin parts, 22 % of its vertices, 71-84 %. At most
  /// about kThicknessSample vertices are measured (those whose index hashes to 0 modulo k, for the
  /// smallest k that leaves at most that many): `sampled` says so.
  double vertex_limit = 0;
  std::size_t vertices_thinner = 0, regular_thinner = 0;
  std::size_t vertices_thicker = 0, regular_thicker = 0;
  bool sampled = false;
};

/// Vertices thin_parts() measures the thickness at, at most. A vertex where the input is thinner
/// costs little (ReferenceSurface::opposite_side_within stops at the first triangle across), one
/// where it is thicker 3-7 us (the search must find none). Measured, one thread, Table 4.2 setup,
/// against the earlier search that collected the whole ball and found the nearest: cheese refined
/// (5 213 vertices, all but 6 thinner) 0.205 -> 0.005 s, cow refined (6 121) 0.027 -> 0.014 s,
/// armadillo simplified (10 124) 0.173 -> 0.059 s, nefertiti simplified (11 408) 0.151 -> 0.063 s,
/// the same counts. A share estimated from that many is within half a point; from 5 000 a point
/// (cow: 89.5 % regular where thick against 89.4 %, spot 88.9 against 89.1 %: the sample made spot
/// look less regular where thick than overall).
constexpr std::size_t kThicknessSample = 20000;

/// The reference's thickness at vertex v of `mesh`: the distance from v to the nearest reference
/// triangle facing the other way, along v's normal (ReferenceSurface::opposite_side_distance); only
/// triangles nearer than `limit` count. Infinity when there is none, or v's normal is zero.
double thickness_at(const TriMesh& mesh, const ReferenceSurface& reference, OpenMesh::VertexHandle v, double limit);
/// Whether thickness_at(mesh, reference, v, limit) < limit (ReferenceSurface::opposite_side_within:
/// the search stops at the first triangle).
bool thinner_than(const TriMesh& mesh, const ReferenceSurface& reference, OpenMesh::VertexHandle v, double limit);

/// Counts the edges of `mesh` outside [e_min, e_max], those of them in thin parts of `reference`
/// (see the file comment) and those at irregular vertices, and the regular vertices by the
/// reference's thickness (ThinParts::vertex_limit), on up to `threads` threads.
/// With `creases` (the run's CreaseGuard under keep_creases), also the edges outside at them.
ThinParts thin_parts(const TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                     unsigned threads = 1, const CreaseGuard* creases = nullptr);

}  // namespace remesh
