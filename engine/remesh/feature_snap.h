#pragma once
/// \file feature_snap.h
/// Not in the thesis: keeps the reference's vertices on the remeshed surface where it would cut
/// them off. The tangential filter pulls vertices away from the apex of a tip (an ear, a horn) or
/// the line of a crease, and the projection brings them back to the surface beside it, so the
/// remeshed surface cuts the tip: the largest distance from the input to the output (one half of
/// the Hausdorff distance) lies at such a reference vertex.
///
/// The same holds along a crease of the reference between its vertices: where two faces meet at
/// more than 20 degrees, a mesh edge that crosses the crease between vertices on either face cuts
/// under it (eight.off, a coarse input whose waist creases meet at 38 degrees: 0.26 units, the
/// largest distance of the run). So the points are the interior reference vertices and, when the
/// run gives a spacing (equalize: crease_spacing(), e_min but at least a quarter of (e_min +
/// e_max) / 2, which is more than e_min only when e_max > 7 e_min), points along every such crease
/// at most that far apart.
///
/// In the last iteration of a run (converged, stalled or n reached), up to kSnapPasses passes:
/// every such point farther from the mesh than a tenth of e_min and at least
/// kFarShare of the farthest one's distance takes its nearest mesh vertex (farthest first), which
/// moves onto it while the 2-ring around it relaxes (snap_to_features in interval_cleanup.h). A
/// move is kept only if it folds nothing, leaves no more edges of the patch outside
/// [e_min, e_max], brings the point nearer, and pulls no other of the points near the patch
/// farther from it than that vertex or the point was (GapJudge in interval_cleanup.cpp). For the
/// points from kPartialShare of the farthest distance, a refused move is retried over 85, 70, 55,
/// 40, 25, 15 and 8 % of the way (a horn too thin for a vertex at its apex with edges in the
/// interval still gets one near it; nefertiti's farthest point, a bump 1.16 from its nearest mesh
/// vertex whose edges are at 1.77-1.78, takes 15 %). The moved vertex lies on the reference; the relaxed ones
/// are projected onto it. The passes share a budget of patch relaxations, one per kSnapBudgetPer
/// vertices of the mesh (at least kSnapBudgetMin): about the cost of one iteration's projection.
/// A pass after the first measures again only the points near a vertex the last pass moved.
/// Measured (Table 4.2 setup, Hausdorff in % of the bbox diagonal, exact distances; before ->
/// after, CGAL's in brackets): spot 0.65 -> 0.44 (0.63), bunny 0.77 -> 0.67 (0.69),
/// kitten 0.39 -> 0.33 (0.40), fandisk 0.645 -> 0.52 (0.65). With the crease points: eight
/// 0.46 -> 0.43 (0.33), mountain 0.169 -> 0.139 (0.190), bunny_zipper 0.205 -> 0.174 (0.265),
/// nefertiti 0.185 -> 0.175 (0.193), but bunny 0.64 -> 0.68 (0.69): another snap order, another
/// local optimum; about 3 % more time on nefertiti and mountain.

#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"
#include "remesh/point_index.h"
#include "remesh/reference_surface.h"

namespace remesh {

class FeatureSnap {
 public:
  /// Collects the interior vertices of `reference` (a valid mesh, typically the input) and, when
  /// `crease_spacing` > 0, points along its creases at most that far apart (see the file comment),
  /// each position once however often the reference repeats it (parts laid over each other).
  explicit FeatureSnap(const TriMesh& reference, double crease_spacing = 0);

  /// The snap of a run's last iteration: up to kSnapPasses passes within the budget. Precondition:
  /// `mesh` has no deleted elements. Returns the number of moves kept. Deterministic (the order is
  /// fixed; the distance queries run in parallel). With `creases`, no vertex leaves a crease
  /// (snap_to_features).
  std::size_t apply(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                    unsigned threads, const CreaseGuard* creases = nullptr) const;

  /// One pass; each patch relaxation takes one from `budget`. Returns the number of moves kept.
  std::size_t pass(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max, unsigned threads,
                   std::size_t& budget, const CreaseGuard* creases = nullptr) const;

  /// apply()'s budget of patch relaxations for a mesh of `vertices` vertices.
  static std::size_t budget_for(std::size_t vertices);

  std::size_t size() const { return points_.size(); }

 private:
  struct Gaps;
  std::size_t pass(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max, unsigned threads,
                   std::size_t& budget, Gaps& gaps, const CreaseGuard* creases) const;

  PointIndex points_;
};

}  // namespace remesh
