#pragma once
/// \file stellar_operations.h
/// Algorithm 3: walk the priority list; split long edges, collapse short ones, with visited marking,
/// eq. 3.1 repositioning and the safety checks that keep the mesh a valid 2-manifold of unchanged
/// topology with no folded or degenerate triangle:
/// - a split puts its vertex on the edge (eq. 3.1) and refuses to create a degenerate triangle (one
///   below geom::kMinAngle, unless no worse than the one it replaces, within kSplitAngleSlack);
/// - a collapse must pass OpenMesh's is_collapse_ok (link condition), must not fold a triangle,
///   create a degenerate one or an edge longer than collapse_length_limit(); it never collapses an interior
///   edge whose two ends lie on the boundary (that would pinch or join two boundary loops), keeps a
///   boundary vertex on the boundary (an interior vertex collapses onto it; a boundary edge collapses
///   along itself), never closes a boundary loop of 3 edges, and never takes a component below
///   4 vertices (a tetrahedron-sized component does not vanish);
/// - not in the thesis: a collapse keeps a tip where it is (is_tip; the other end collapses onto
///   it, as onto a boundary vertex), unless both ends are tips.
/// The edits leave deleted elements behind: call collect_garbage(mesh) (core/mesh.h) after a pass.

#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"

namespace remesh {

/// Does the connected component of v have more than n live vertices? A search from v that stops
/// at the (n+1)-th vertex: a few steps for a small n, whatever the mesh's size.
bool component_larger_than(const TriMesh& mesh, OpenMesh::VertexHandle v, std::size_t n);

/// Splits edge e at the point of eq. 3.1 (target edge length `target`). Not in the thesis: where
/// that point would make a triangle with an angle under geom::kMinAngle, at the edge's midpoint
/// instead. Returns the new vertex, or an invalid handle when the midpoint would too. With
/// `creases`, the point of an edge along a crease is put on the crease (crease_lines.h).
OpenMesh::VertexHandle split_edge(TriMesh& mesh, OpenMesh::EdgeHandle e, double target,
                                  const CreaseGuard* creases = nullptr);

/// A planned collapse: the halfedge whose from-vertex goes away and where the kept vertex ends up.
struct CollapsePlan {
  OpenMesh::HalfedgeHandle halfedge;
  Vec3 position;
  /// The kept vertex stays where it is (a boundary vertex an interior one collapses onto, or a
  /// kept tip): a later placement must not move it.
  bool kept_in_place = false;
};

/// Angle deficit (radians) above which an interior vertex is a tip (is_tip): the apex of a cone
/// of half-angle below about 30 degrees (deficit 2 pi (1 - sin a); a cube's corner has pi / 2,
/// a smooth surface sampled at the target length far less). Not in the thesis. A collapse by
/// eq. 3.1 puts the merged vertex on the edge, below the tip, and the projection keeps it there:
/// where the remeshed mesh is coarse next to a tip (an ear, a horn, a leg when simplifying) the tip
/// wears away, a little with every iteration (bunny's ear, simplification setup with [1.21, 1.81]:
/// 0.29 from the mesh after iteration 11, 2.73 after the 24th). Measured over five intervals
/// around [1.2, 1.8] (Table 4.2 setup, mean Hausdorff % of the bbox diagonal, without -> with, the
/// check of the new neighbours in collapse_geometry_ok included): refinement cow 1.70 -> 1.41,
/// cheese 4.13 -> 3.70, camelhead 1.27 -> 0.87; simplification cow 4.18 -> 2.93, camelhead
/// 3.82 -> 2.73, bunny 4.45 -> 3.61, fandisk 1.75 -> 1.64, spot 2.29 -> 2.14; kitten, bunny and
/// fandisk refinement about the same. Edges inside fall a little where the kept tips lie in thin
/// parts (cow simplification 93.8 -> 93.6 %, bunny 99.98 -> 99.88 %). Thresholds 1.0 and 2.0
/// gain less.
constexpr double kTipDeficit = 1.5;

/// Is v an interior vertex with an angle deficit above kTipDeficit? (The filter's is_corner,
/// low_pass_filter.h, holds still every vertex with |deficit| > 1 rad, saddles included; as the
/// collapse rule it kept fewer tips: five-interval means, before the check of the new neighbours,
/// cow simplification 2.56 % with this rule, 3.85 % with that one.)
bool is_tip(const TriMesh& mesh, OpenMesh::VertexHandle v);

/// Chooses direction and position (eq. 3.1, the boundary vertex or the tip, see above) for
/// collapsing e and checks every rule. Returns false when the collapse is not allowed. With
/// `keep_tips` false a tip is merged by eq. 3.1 like any vertex: the interval cleanup's collapses
/// (interval_cleanup.h) mend edges outside the interval, and keep tips only with
/// Params::protect_tips, since keeping tips there too left more of
/// them (cheese refinement 99.57 -> 99.45 % inside on average over five intervals, below the
/// 99.5 % the benchmark aims at) for a lower Hausdorff distance (cow 1.41 -> 1.32 %).
/// With `creases`, the collapse also follows CreaseGuard's rule (crease_lines.h): along a crease
/// the point goes onto it and a corner end stays; an end on a crease stays when the edge is not
/// along one; an edge between two creases, or along one between two corners, is refused.
bool plan_collapse(const TriMesh& mesh, OpenMesh::EdgeHandle e, double target, double max_length,
                   CollapsePlan& plan, bool keep_tips = true, const CreaseGuard* creases = nullptr);

/// Would collapsing `h` with the kept vertex at `p` fold or degenerate a triangle, sharpen a pair of
/// adjacent faces past geom::kMinAdjacentCos (those around its ends, and the two that become
/// neighbours where each removed face was), or create an edge longer than max_length? (Geometric
/// part of plan_collapse; topology is checked there.) With `turned_ok`, the faces need not keep their
/// normals' directions (untangle.h: a tangle's faces are turned already); the tests of adjacent
/// faces still refuse a face turned over against its neighbours.
bool collapse_geometry_ok(const TriMesh& mesh, OpenMesh::HalfedgeHandle h, const Vec3& p, double max_length,
                          bool turned_ok = false);

/// Carries out a plan; returns the kept vertex.
OpenMesh::VertexHandle apply_collapse(TriMesh& mesh, const CollapsePlan& plan);

/// The longest edge a collapse of Algorithm 3 may create: max(m_i + sigma, 2 (m_i - sigma)).
/// ALGORITHM.md asks for m_i + sigma. Measured on spot.obj (Table 4.2 setup, 100 iterations) that
/// bound refuses 99 % of the collapses of short edges once the mesh is near the target (a short edge
/// between ordinary ones has far neighbours at about 1.4 m_i from the merged vertex), the mesh stays
/// 7 % too dense and ends at 95.9 % inside / 80.7 % regular; without any bound it ends at 99.7 % /
/// 88.3 % (the thesis, on its Fertility model: 99.65 % / 89.6 %). 2 (m_i - sigma) keeps a bound
/// with a reason: an edge up to that long splits into two halves that are not short. For
/// [1.2, 1.8] it is 2.4.
double collapse_length_limit(double m_i, double sigma);

struct StellarCounts {
  std::size_t splits = 0, collapses = 0;
};

/// Algorithm 3 over `list` (edge indices, worst first): long (> m_i + sigma) -> split, short
/// (< m_i - sigma) -> collapse; skips edges that are gone or whose ends were both visited. With
/// `creases`, splits and collapses keep the creases (split_edge, plan_collapse).
/// With `placed`, the vertices whose point an operation chose (a split's new vertex, a collapse's
/// kept one when it moved) are appended to it.
StellarCounts stellar_operations(TriMesh& mesh, const std::vector<unsigned>& list, double m_i, double sigma,
                                 const CreaseGuard* creases = nullptr,
                                 std::vector<OpenMesh::VertexHandle>* placed = nullptr);

}  // namespace remesh
