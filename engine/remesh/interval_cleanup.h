#pragma once
/// \file interval_cleanup.h
/// Not in the thesis: its conclusion asks for a post-process that removes the last edges outside
/// [e_min, e_max]; this is it. It runs after the last iteration (Params::cleanup). For each edge
/// still outside the interval, worst first, it tries in order the local fixes below and keeps the
/// first that is safe (no fold, no degenerate triangle, no topology change: the same checks as the
/// stellar operations) and strictly lowers the number of edges outside the interval around it:
///   1. flip a long or short interior edge whose other diagonal lies inside the interval (the four
///      edges around it do not change);
///   2. collapse a short edge, the kept vertex placed by eq. 3.1 and projected onto the reference,
///      if every edge it ends up with lies inside the interval;
///   3. split a long edge, the new vertex placed by eq. 3.1 and projected, if its four (three on the
///      boundary) edges lie inside;
///   4. relocate an interior end vertex within its tangent plane (a few gradient steps on the squared
///      distance of its edge lengths to the interval), project it, keep it if fewer of its edges
///      are outside and none of its faces folds.
/// Rounds repeat while they fix something (at most `rounds`). Every vertex it creates or moves lies
/// on the reference surface, so the Hausdorff distance does not grow; on a mesh whose edges are all
/// inside it does nothing (idempotent).

#include <cstddef>
#include <cstdint>
#include <stop_token>
#include <utility>
#include <vector>

#include "core/mesh.h"
#include "remesh/crease_lines.h"
#include "remesh/point_index.h"
#include "remesh/reference_surface.h"

namespace remesh {

struct CleanupCounts {
  std::size_t flips = 0, collapses = 0, splits = 0, relocations = 0, patches = 0;
  std::size_t outside_before = 0, outside_after = 0;  ///< edges outside [e_min, e_max]
  /// Edges passed over because no fix could mend them last time and nothing near them changed.
  std::size_t skipped = 0;
  /// Patch relaxations passed over because the edge's ends keep failing (PatchRest, through
  /// CleanupOptions::rest); each took one from the budget, as the failure it stands for would.
  std::size_t rested = 0;
};

/// Where patch relaxations failed, across the per-iteration cleanups of one run (CleanupOptions::
/// rest). Each vertex holds the last cleanup in which the patch relaxation of one of its edges
/// failed, and the length of its row of such cleanups (a row: cleanups with a failure right after
/// the rest the one before gave, so that a rest does not break it; a success or an edge not tried
/// in between does not either). A cleanup passes over the patch of an edge whose two ends are both
/// resting, at the cost of one from the budget as the failure would have taken: an end rests for
/// rest_after(row) cleanups after its last failure, 1 in a row of kRow, then 2, 4 and at most 8
/// (kMaxRestShift): a patch that keeps failing is tried ever more rarely. The memory is
/// per vertex, not per edge: the ends may have failed through other edges of theirs; and an end
/// that fails again within the cleanup no longer rests its edges there (more tries, never fewer).
/// Kept as a vertex property of the mesh, so that it follows the vertices through garbage
/// collection; a mesh rebuilt from scratch (spatial_order, a snapshot) starts with none. The run's
/// mesh is returned without it.
/// Why: a run that stalls (edges where the input is thinner than the interval allows) spends its
/// per-iteration cleanups on the same patches, which fail again: cheese refined, iterations
/// 13-24, 59 of each cleanup's 64 patches had failed at the same edge the iteration before, and 3
/// of those 700 succeeded; 30 % of the run's time. A patch that fails leaves the mesh as it was,
/// so resting one changes the run only where it would have succeeded. Measured (bench --spread,
/// 2 threads, each mesh-setup's five intervals run in turn with and without, twice): the eight
/// stalled mesh-setups (cheese, cow and camelhead both ways, bunny and spot simplified) 8.6 and
/// 5.6 % less time (cheese simplified 16 %, cow simplified 13-15 %), inside -0.01 points on average (16
/// runs better, 13 worse of 40), Hausdorff 2.5 % more (geometric mean), crossing face pairs 491
/// against 535. Resting after one failure instead changed the runs that converge (armadillo
/// refined took 1-2 more iterations on 3 of 5 intervals); after two it gives the same meshes
/// there (40 of the 55 refinements of 11 meshes unchanged). Rests that double with the row
/// (build after 06c4d2c; before, every other cleanup): 16 mesh-setups of both setups, five
/// intervals, 3.7 % less time in all (cow simplified 0.41 -> 0.36 s, cheese refined 1.83 -> 1.75,
/// camelhead 5-7 %), inside 97.526 -> 97.527 % on average, regular -0.02 points, Hausdorff +0.4 %
/// (geometric mean; cow simplified 2.42 -> 2.52 %); 11 of the 16 gave the same figures on all five.
class PatchRest {
 public:
  explicit PatchRest(TriMesh& mesh) : mesh_(mesh) {}
  ~PatchRest();
  PatchRest(const PatchRest&) = delete;
  PatchRest& operator=(const PatchRest&) = delete;
  /// Starts the next cleanup (adds the property if the mesh has none; the first call replaces one
  /// the mesh came with).
  void begin();
  /// Are both a and b resting: each failed (a patch relaxation of one of its edges) within its
  /// last rest_after(row) cleanups, not in this one?
  bool resting(OpenMesh::VertexHandle a, OpenMesh::VertexHandle b) const;
  /// A patch relaxation of the edge ab failed in this cleanup.
  void failed(OpenMesh::VertexHandle a, OpenMesh::VertexHandle b);

  /// The property's name and record: a vertex's failures, the cleanup of the last (numbered from 1
  /// by begin()) and the length of its row.
  static constexpr const char* kName = "remesh:patch_failed";
  struct Failures {
    std::uint32_t at = 0, row = 0;
  };

 private:
  /// Failures in a row before an end rests.
  static constexpr std::uint32_t kRow = 2;
  /// The longest rest, 2^kMaxRestShift cleanups.
  static constexpr std::uint32_t kMaxRestShift = 3;
  /// Cleanups an end rests after its last failure, in a row of `row` (0 below kRow).
  static std::uint32_t rest_after(std::uint32_t row);
  TriMesh& mesh_;
  OpenMesh::VPropHandleT<Failures> at_;
  std::uint32_t cleanup_ = 0;
};

/// How one cleanup runs (equalize.cpp: a per-iteration and a final form).
struct CleanupOptions {
  /// Rounds at most; the cleanup stops earlier after a round that fixes nothing.
  int rounds = 4;
  /// Only edges with an end on the boundary are treated. On open meshes a cleanup of this form runs
  /// every iteration, because boundary vertices never move in the filter and split/collapse alone
  /// cannot even out a boundary whose edges are, say, 1.1 m long.
  bool boundary_only = false;
  /// Cap on the patch relaxations (fix 4's stronger form, a few hundred projections each); 0 means
  /// max(64, edges / 1000), enough for the few stubborn edges of a nearly converged mesh, not for
  /// thousands in a rough one.
  std::size_t patch_budget = 0;
  /// The projection's per-vertex kd-tree answers (projection.h), reused and refreshed by the
  /// cleanup's projections (exact either way); may be null.
  std::vector<NeighbourCache>* caches = nullptr;
  /// Pass over an edge that no fix could mend, while nothing within 4 rings of it has changed
  /// since, and a relocation that failed, while nothing within 2 rings of its vertex has (each
  /// would fail again). The result is the same either way; off only to check that.
  bool remember_failures = true;
  /// Params::protect_tips: tips (is_tip) are never moved (collapses keep them, relocations and
  /// patch relaxations pass them over).
  bool protect_tips = false;
  /// Checked between rounds and every kStopCheckEvery edges of a round: a request ends the cleanup
  /// there, the mesh valid (each fix is whole). A round on a pathological input (a polygon of
  /// thousands of sides) can take seconds, and a cancelled job waited for it.
  std::stop_token stop;
  /// The reference's creases to keep (CreaseGuard, crease_lines.h): its flips, splits, collapses
  /// and vertex moves follow the guard's rule. May be null.
  const CreaseGuard* creases = nullptr;
  /// The run's patch memory (PatchRest); null: every patch is tried (the final cleanup's form,
  /// which has no next iteration to leave a patch to).
  PatchRest* rest = nullptr;
};

/// Runs the cleanup. Precondition: no deleted elements (garbage-collected); it leaves the mesh
/// garbage-collected too. `flip_factor` is Params::flip_factor.
CleanupCounts interval_cleanup(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                               double flip_factor, const CleanupOptions& options = {});

/// A move of the feature snap (feature_snap.h): vertex v onto target, a point of the reference.
/// With `partial`, when the whole move is refused, fractions of it are tried in turn (for the
/// points that decide the Hausdorff distance: the search costs a patch relaxation per fraction).
struct SnapMove {
  OpenMesh::VertexHandle v;
  Vec3 target;
  bool partial = false;
};

/// Makes each move and relaxes the interior vertices within 2 rings of the moved vertex, as the
/// patch relaxation does; keeps a move only if it folds nothing, leaves no more edges of the patch
/// outside [e_min, e_max] than before, brings its target nearer to the mesh, and leaves none of the
/// `features` points near the patch farther from it than the larger of that point's and the
/// target's distance before. With `creases`, a vertex on a crease is not moved off it: a move of
/// one is refused, and a relaxed one slides along its crease. Each try (a patch relaxation) takes one from `budget`; none is made
/// when it is 0. Returns the number of moves kept.
std::size_t snap_to_features(TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                             const std::vector<SnapMove>& moves, const PointIndex& features,
                             std::size_t& budget, const CreaseGuard* creases = nullptr);

}  // namespace remesh
