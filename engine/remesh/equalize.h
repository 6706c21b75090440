#pragma once
/// \file equalize.h
/// Iterative edge-length equalization (the thesis' Algorithm 1, as ../shared/ALGORITHM.md reads it):
///
///   for i = 1..n:
///     if pr > 0 and i % pr == 0: reference = copy(mesh)
///     m_i = min(2 * mean_edge_length(mesh), m)
///     stellar operations on the priority list     (Algorithms 2, 3; eq. 3.1 repositioning)
///     valence-improving flips                     (Algorithm 4)
///     tangential k-ring low-pass filter           (Algorithm 5)
///     projection onto the reference surface       (Algorithm 6)
///     report the statistics row; stop if cancelled or converged

#include <algorithm>
#include <cstddef>
#include <functional>
#include <optional>
#include <stop_token>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "remesh/params.h"
#include "remesh/preconditions.h"  // the checks equalize() makes first, as_run
#include "remesh/thin_parts.h"
#include "remesh/triangle_quality.h"

namespace remesh {

/// One row per iteration. Field names are stable: the API, CSV and JSON use them as they are.
struct IterationStats {
  int iteration = 0;
  std::size_t vertices = 0, edges = 0;
  double mean = 0;             ///< mean edge length
  double deviation = 0;        ///< population standard deviation of edge lengths
  double regular_percent = 0;  ///< % of interior vertices with valence 6
  std::size_t small = 0;       ///< edges shorter than e_min
  std::size_t big = 0;         ///< edges longer than e_max
  double inside_fraction = 0;  ///< fraction of edges inside [e_min, e_max], 0..1
  std::size_t splits = 0, collapses = 0, flips = 0;
  double seconds = 0;                  ///< wall time of this iteration
  /// largest distance a vertex moved in this iteration's projection (Algorithm 6), measured before
  /// the fold guard puts some vertices back (fold_guard.h); the projection of the points the
  /// stellar operations placed is not counted
  double max_projection_distance = 0;
  /// Local fixes made by the interval cleanup (Params::cleanup) in this iteration; they are also
  /// counted in splits, collapses and flips. Non-zero once the mesh is nearly inside the interval
  /// (and on open meshes, near the boundary, in every iteration).
  std::size_t cleanup_fixes = 0;
};

using OnIteration = std::function<void(const IterationStats&)>;

/// Completed: ran all iterations. Converged: stopped early with every edge inside [e_min, e_max].
/// Stalled: stopped early because the count of edges outside stopped falling (stopping_rule.h),
/// with edges outside left. (A stalled run whose last step mends its last edges is Converged.)
/// Cancelled: the stop token was triggered. Only Completed happens with run_all_iterations.
enum class Outcome { Completed, Converged, Stalled, Cancelled };

/// "completed", "converged", "stalled" or "cancelled" (the API, CLI and benchmark print these).
const char* outcome_name(Outcome o);

/// Wall seconds a run spent in each of its steps, summed over its iterations: where the time goes
/// (the benchmark, the CLI and the job document show them). Statistics rows, snapshots of the best
/// mesh so far and the thin-part count make up the rest of Result::seconds.
struct PhaseSeconds {
  double stellar = 0;     ///< priority list, stellar operations, garbage collection (Alg. 2, 3), and
                          ///< the numbering in space order of a large mesh after them (spatial_order.h)
  double flips = 0;       ///< valence flips (Alg. 4) and look-ahead flips (regularize.h)
  double filter = 0;      ///< low-pass filter (Alg. 5)
  double projection = 0;  ///< projection onto the reference (Alg. 6)
  double guards = 0;      ///< undoing folds and interval breaks of the filter and projection (fold_guard.h)
  double cleanup = 0;     ///< interval cleanups: the iterations', the final one, the untangling's mends
  double snap = 0;        ///< feature snap (feature_snap.h)
  double untangle = 0;    ///< moving crossing faces apart (untangle.h), its mends not included
  double setup = 0;       ///< reference surface, its kd-tree and feature points (and again at each `pr`),
                          ///< and the first numbering in space order of a large input
  double sum() const;  ///< of every step (kPhaseFields)
};

/// The steps of PhaseSeconds by name, in the order of a run (the CLI, the API and the benchmark
/// name them so).
struct PhaseField {
  const char* name;
  double PhaseSeconds::*seconds;
};
inline constexpr PhaseField kPhaseFields[] = {
    {"stellar", &PhaseSeconds::stellar}, {"flips", &PhaseSeconds::flips},   {"filter", &PhaseSeconds::filter},
    {"projection", &PhaseSeconds::projection}, {"guards", &PhaseSeconds::guards}, {"cleanup", &PhaseSeconds::cleanup},
    {"snap", &PhaseSeconds::snap},       {"untangle", &PhaseSeconds::untangle}, {"setup", &PhaseSeconds::setup}};

inline double PhaseSeconds::sum() const {
  double total = 0;
  for (const PhaseField& f : kPhaseFields) total += this->*f.seconds;
  return total;
}

/// The rest of a run's `seconds` outside the steps (statistics rows, snapshots), never negative.
inline double other_seconds(const PhaseSeconds& phases, double seconds) { return std::max(0.0, seconds - phases.sum()); }

/// "stellar 0.045, flips 0.041, ..., setup 0.002, other 0.013": each step's seconds and the rest
/// of `seconds`, to the millisecond.
std::string describe_phases(const PhaseSeconds& phases, double seconds);

struct Result {
  Outcome outcome = Outcome::Completed;
  int iterations_done = 0;
  double seconds = 0;
  PhaseSeconds phases;  ///< how `seconds` divides between the steps
  /// The returned mesh's edges outside the interval, and how many of them lie where the input is
  /// too thin for any edge there to be inside (thin_parts.h).
  ThinParts thin;
  /// The returned mesh's pairs of faces that cross each other (find_self_intersections: faces
  /// sharing an edge never count, touching ones neither), after the untangling; left where the
  /// input crosses itself or parts are thinner than the edges. Unknown for a cancelled run, and for
  /// a layered one.
  std::optional<std::size_t> crossing_pairs;
  /// The returned mesh lies over itself throughout (lies_over_itself: a part duplicated in place,
  /// shells stacked on each other): its crossing pairs were neither counted nor moved apart.
  bool layered = false;
  /// The returned mesh's triangle shapes (triangle_quality.h). Unknown for a cancelled run.
  std::optional<TriangleQuality> triangles;
};

/// The spacing of the feature snap's points along the reference's creases (feature_snap.h): e_min,
/// but never less than a quarter of m = (e_min + e_max) / 2. With [1.2, 1.8] it is e_min; an
/// interval like [1e-7, 1] would otherwise put a point every 1e-7 along every crease, hundreds of
/// millions of them before the first iteration (a unit cube: 8 GB), for a mesh whose edges are
/// near 0.5.
double crease_spacing(const Params& params);

/// Remeshes `mesh` in place. Preconditions: a valid 2-manifold, consistently oriented TriMesh (as
/// read_mesh returns). Throws what check_preconditions() throws (preconditions.h): ParamsError if
/// check(params) or check_against(mesh, params) fails, LimitError if the estimated output exceeds
/// params.max_output_faces. Runs with as_run(mesh,
/// params). `on_iteration` runs on the calling thread after each iteration.
/// A stop request is honoured between phases; the mesh is valid whenever this returns.
Result equalize(TriMesh& mesh, const Params& params, const OnIteration& on_iteration = {},
                std::stop_token stop = {});

/// Statistics of a mesh against an interval, as a row with iteration 0 and zero counters.
IterationStats measure(const TriMesh& mesh, double e_min, double e_max, unsigned threads = 0);

}  // namespace remesh
