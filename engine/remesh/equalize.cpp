#include "remesh/equalize.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "remesh/crease_lines.h"
#include "remesh/feature_snap.h"
#include "remesh/fold_guard.h"
#include "remesh/geometry.h"
#include "remesh/interval_cleanup.h"
#include "remesh/low_pass_filter.h"
#include "remesh/mesh_snapshot.h"
#include "remesh/self_intersections.h"
#include "remesh/spatial_order.h"
#include "remesh/untangle.h"
#include "remesh/priority_list.h"
#include "remesh/projection.h"
#include "remesh/reference_surface.h"
#include "remesh/regularize.h"
#include "remesh/statistics.h"
#include "remesh/stellar_operations.h"
#include "remesh/stopping_rule.h"
#include "remesh/valence_flips.h"

namespace remesh {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Adds the wall time from its construction (or switch_to) to stop() or its destruction to a
/// PhaseSeconds field.
class PhaseTimer {
 public:
  explicit PhaseTimer(double& total) : total_(&total) {}
  ~PhaseTimer() { stop(); }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;
  /// Ends the phase timed so far and times `next` from now.
  void switch_to(double& next) {
    stop();
    total_ = &next;
    start_ = Clock::now();
  }
  void stop() {
    if (total_) *total_ += seconds_since(start_);
    total_ = nullptr;
  }

 private:
  double* total_;
  Clock::time_point start_ = Clock::now();
};

/// The half-width of the main phase's band, m_i +- sigma (the priority list and the stellar
/// operations, Alg. 2 and 3): (e_max - e_min) / 2 as in ALGORITHM.md, but never less than
/// kMinBand m. Not in the thesis, whose setup is [1.2, 1.8], +-20 % of m, where the two agree. A
/// narrower band makes the stellar operations split and collapse edges that the filter would
/// even out anyway, every iteration, and the churn spreads the lengths instead of narrowing them
/// (bunny refinement, [1.35, 1.65]: deviation 0.18 against 0.11 with [1.2, 1.8]); the interval
/// cleanup then works to the interval itself. Measured (Table 4.2 meshes scaled to mean edge
/// 2.25): with [1.35, 1.65] (+-10 %) bunny, kitten, spot, fandisk and cow end 68.5-69.7 % inside
/// with the interval's own band and 91.0-92.2 % with this one; bunny with [1.3125, 1.6875]
/// (+-12.5 %) 91.6 -> 99.2 %. A floor of 0.25 m does worse (88.1 and 97.2 %) and would change
/// the [1.2, 1.8] runs.
constexpr double kMinBand = 0.2;
double main_phase_sigma(const Params& params) {
  const double sigma = 0.5 * (params.e_max - params.e_min), floor = kMinBand * 0.5 * (params.e_min + params.e_max);
  return sigma >= floor * (1 - 1e-9) ? sigma : floor;  // [1.2, 1.8] keeps its own sigma to the last bit
}

/// Not in the thesis: the half-width of an iteration's band is at most kMaxBandShare m_i. The
/// thesis keeps sigma, the final interval's, while m_i (twice the mean edge) grows toward m. On an
/// input much finer than the target, m_i - sigma is then 0 or less: no edge is short, nothing
/// collapses, and the run stalls with the input unchanged, 0 % inside. With the cap, edges shorter
/// than m_i / 2 (the current mean edge) are always short. The thesis' band is kept while
/// m_i >= 2 sigma: for [1.2, 1.8], while the mean edge is at least 0.3, that is for targets up to
/// 5x the input's mean edge. So the Table 4.1 and 4.2 runs give the same meshes. Measured (target
/// k x the input's mean edge, interval +-20 %; inside %, vertices, seconds; before -> after):
///   nefertiti k=8: 0 %, 46 983, 58.3 s -> 100 %, 694, 1.5 s (Hausdorff 2.25 % of the bbox
///                  diagonal; CGAL at the same target: 2.26 %, 818 vertices);
///   spot k=8:      0 %, 2 649, 3.7 s -> 100 %, 46, 0.11 s;
///   fandisk k=8:   0 %, 6 456, 8.9 s -> 100 %, 73, 0.23 s;
///   kitten k=12:   0 %, 10 000, 10.3 s -> 98.5 %, 65, 0.43 s.
/// Scaling sigma by m_i / m instead changed the runs from 2x to 5x as well, with no better
/// outcome (regular vertices 6-9 points lower on spot, bunny and kitten at k=6).
constexpr double kMaxBandShare = 0.5;
double band_at(double sigma, double m_i) { return std::min(sigma, kMaxBandShare * m_i); }

/// Flip sweeps per iteration: the thesis does one; further sweeps catch the flips the first one
/// enabled and raise regularity for little time.
constexpr int kFlipSweeps = 3;
/// Sweeps of the look-ahead flips per iteration (regularize.h), at most.
constexpr int kRegularizeSweeps = 4;

/// Fraction of edges inside [e_min, e_max] from which the interval cleanup runs every iteration.
/// Measured on spot.obj (Table 4.2 setup): from 0.97 the run converges (100 % inside) after 18
/// iterations with 85 % regular vertices; from 0.99 after 52 with 86.7 %; cleanup in every iteration
/// costs regularity (81 %), since its fixes fight the valence flips.
constexpr double kCleanupFrom = 0.97;

/// Iterations of the interval cleanup after which the filter and projection (Alg. 5 and 6) may no
/// longer take an edge out of the interval: a vertex whose move does goes half way back, up to
/// three times, then all the way (undo_interval_breaks, fold_guard.h). Until then only the fold
/// guard holds them back, as in every iteration. In a run that stalls, they took ~540 edges out of
/// the interval in every iteration (cow refinement, iterations 15-31: 5-30 edges outside after the
/// stellar operations and flips, ~550 after the filter and projection), which the cleanup then
/// mended again; the edges it could not mend wandered, and so did the tips it cut. Measured (Table
/// 4.2 setup, the means over the five intervals of bench --spread, Hausdorff in % of the bbox
/// diagonal; before -> after, with kExploreAfter): cow refinement 1.43 -> 1.22 (worst 1.86 ->
/// 1.29), cheese 3.77 -> 2.90 (worst 4.80 -> 3.13) and 2.60 -> 1.84 s; simplification: cow 93.4 ->
/// 94.5 % inside, cheese 6.3 -> 4.7 s; cheese's regular vertices 69.4 -> 67.2 %, bunny's simplified
/// 85.1 -> 84.2 %. Runs that converge within kSteadyAfter iterations of the cleanup (spot, bunny,
/// eight, kitten) give the same meshes. Guarding from the cleanup's start on cost regularity (eight
/// 86.5 %, cow 86.9 % in single runs): the smoothing it holds back; after 2 or 5 iterations it
/// gained less.
constexpr int kSteadyAfter = 3;
/// ... unless the run has reached no new low of edges outside for this many iterations: then the
/// filter moves freely again, until the next low. Its churn is what lets the cleanup find another
/// arrangement where it is stuck (a cone of half-angle 18 degrees, equalize_test: guarded in every
/// iteration, it stalls with 3 edges outside; with this rule it converges). Measured on the same five-interval
/// runs: cow 1.22, cheese 2.90 (1.85 s) against 1.23 and 2.94 guarded in every iteration, and the
/// same meshes as before on bunny, spot, eight and kitten. Guarding every other iteration
/// instead kept less: cheese 3.50.
constexpr int kExploreAfter = 2;

/// Not in the thesis: a mesh of at least kOrderMinVertices vertices is numbered anew in space order
/// (spatial_order.h) at the start, and after the stellar operations of an iteration once the splits
/// and collapses since the last numbering reach kOrderShare of its vertices. Measured (Table 4.2
/// setup, 2 threads, means over the five intervals of bench --spread): armadillo 7.46 -> 3.98 s,
/// nefertiti 10.1 -> 6.1 s (each numbering takes 30-40 ms there, 13 in its run), with the same
/// quality within the runs' spread. A share of 0.05 gave 4.08 and 6.24 s, 0.15 4.33 and 7.01 s,
/// every iteration 4.43 and 6.72 s; 0.02 measured again gave 4.55 and 6.72 s, so only the last two
/// are clearly slower. Below ~16 000 vertices the mesh stays in the caches: fandisk (13 000) gained
/// nothing per iteration; smaller meshes keep their numbering, and so their meshes bit for bit.
constexpr double kOrderShare = 0.02;
constexpr std::size_t kOrderMinVertices = 16384;

/// How near a crease of the reference (crease_lines.h) a vertex lies on it: kOnCrease of the
/// bounding box's diagonal, or kOnCreaseFar of its largest coordinate when that is more. A vertex
/// projected onto a crease lands on it within the arithmetic's last bits, and those are bits of its
/// coordinates: a cylinder 1e8 from the origin lost its rims to a tolerance of the diagonal alone
/// (99.4 % inside, vertices 0.22 off the surface; at the origin 100 %, on the surface), measured
/// while the filter moved a crease vertex along a straight line; sliding along the crease it
/// converges either way (25 iterations with this tolerance, 20 without).
constexpr double kOnCrease = 1e-9, kOnCreaseFar = 1e-12;
double crease_tolerance(const TriMesh& mesh) {
  double far = 0;
  for (auto v : mesh.vertices()) far = std::max(far, mesh.point(v).max_abs());
  return std::max(kOnCrease * bounding_box_diagonal(mesh), kOnCreaseFar * far);
}

/// Rounds of the interval cleanup per iteration (it stops earlier when a round fixes nothing).
constexpr int kCleanupRounds = 6;

double inside_fraction(const TriMesh& mesh, const Params& params, unsigned threads) {
  return measure(mesh, params.e_min, params.e_max, threads).inside_fraction;
}

/// Has the main phase stopped gaining edges inside the interval? True when, over the last
/// kPlateauSpan iterations, the fraction inside rose by less than kPlateauGain or the fraction
/// outside shrank by less than kPlateauShrink of itself. Measured on fandisk.obj (Table 4.2 setup):
/// the main phase alone creeps from 95 to 96.7 % inside over iterations 10-21, splitting and
/// collapsing hundreds of edges around the sharp features every iteration; the relative rule starts
/// the cleanup at iteration 14 instead of 21. Nor has it stopped while the edge count still
/// changes by more than kPlateauEdgeChange over the span: a simplification collapses a tenth of its
/// edges or more per iteration for its first ten or so, with the fraction inside flat or falling
/// meanwhile (cheese.off, mean edge 0.75 -> [1.2, 1.8]: 30 % inside at iteration 1, 26 % at 5),
/// and a cleanup started then works on edges the next collapses remove anyway. Measured (the same
/// setup, means over the five intervals of bench --spread): cheese's simplification 4.80 -> 2.25 s,
/// 64.75 -> 64.93 % inside, Hausdorff 6.49 -> 6.06 % of the bbox diagonal; the same meshes on the
/// other 21 mesh-setups (their edge counts change less by the time the rule fires).
constexpr int kPlateauSpan = 3;
constexpr double kPlateauGain = 0.002;
constexpr double kPlateauShrink = 0.15;
constexpr double kPlateauEdgeChange = 0.10;
bool plateaued(const std::vector<IterationStats>& history) {
  const std::size_t n = history.size();
  if (n <= kPlateauSpan) return false;
  const IterationStats &last = history[n - 1], &first = history[n - 1 - kPlateauSpan];
  const double edges_now = static_cast<double>(last.edges), edges_then = static_cast<double>(first.edges);
  if (std::abs(edges_now - edges_then) > kPlateauEdgeChange * edges_then) return false;
  const double now = last.inside_fraction, then = first.inside_fraction;
  return now - then < kPlateauGain || (1.0 - now) > (1.0 - kPlateauShrink) * (1.0 - then);
}

/// The final cleanup of a run that ends with edges outside (stalled, or n reached): the mesh it
/// returns, its low, gets one more interval cleanup, with rounds until one fixes nothing and a
/// larger patch budget than the per-iteration cleanups (which share max(64, edges / 1000) per
/// iteration and spend it all on such a run). No main phase comes after it to undo its fixes.
/// Measured (Table 4.2 setup): cheese refine 115 -> 72 edges outside (99.28 -> 99.55 % inside)
/// for 0.03 s; with a budget of 64 it reaches 93, with 150 or more 72. Cheese simplify spends 0.5 s
/// of 14.8 with 300 and fixes one edge (1000: 1.5 s, the same edge).
constexpr int kFinalCleanupRounds = 30;
std::size_t final_patch_budget(const TriMesh& mesh) { return std::max<std::size_t>(300, mesh.n_edges() / 100); }

/// The interval cleanup with the run's options: an iteration's (kCleanupRounds, the default patch
/// budget; `boundary_only` before the full cleanup starts) or, with `final`, the final cleanup's
/// (kFinalCleanupRounds, final_patch_budget).
CleanupCounts run_cleanup(TriMesh& mesh, const ReferenceSurface& reference, const Params& params,
                          std::vector<NeighbourCache>& caches, const CreaseGuard* creases, bool final,
                          bool boundary_only = false, std::stop_token stop = {}, PatchRest* rest = nullptr) {
  CleanupOptions options;
  options.rounds = final ? kFinalCleanupRounds : kCleanupRounds;
  if (final) options.patch_budget = final_patch_budget(mesh);
  options.boundary_only = boundary_only;
  options.caches = &caches;
  options.protect_tips = params.protect_tips;
  options.stop = std::move(stop);
  options.creases = creases;
  options.rest = final ? nullptr : rest;
  return interval_cleanup(mesh, reference, params.e_min, params.e_max, params.flip_factor, options);
}

std::size_t fixes(const CleanupCounts& c) { return c.flips + c.collapses + c.splits + c.relocations + c.patches; }

/// Adds a cleanup's fixes and its splits, collapses and flips to a row's counters.
void count_cleanup(IterationStats& row, const CleanupCounts& c) {
  row.cleanup_fixes += fixes(c);
  row.splits += c.splits;
  row.collapses += c.collapses;
  row.flips += c.flips;
}

/// The last step of a run (after the feature snap): faces that cross each other are moved apart
/// (untangle.h), which can leave edges outside the interval; a cleanup of the final form mends
/// them, and when it makes faces cross that did not before, they are moved apart again
/// (kUntangleRounds times at most, the last without a cleanup after it: a crossing is worse than an
/// edge a little outside). Measured (Table 4.2 setup): nefertiti 14 -> 0 crossing face pairs, 62
/// edges the flattening left outside mended, 16 -> 5 edges outside in all.
constexpr int kUntangleRounds = 3;

/// A crossing face pair by its six corners' positions, sorted: they stay put when edits elsewhere
/// renumber the faces.
using CrossingKey = std::array<std::array<double, 3>, 6>;
std::vector<CrossingKey> crossing_keys(const TriMesh& mesh, const std::vector<std::pair<unsigned, unsigned>>& pairs) {
  std::vector<CrossingKey> keys;
  keys.reserve(pairs.size());
  for (const auto& [f, g] : pairs) {
    CrossingKey key;
    int i = 0;
    for (unsigned face : {f, g})
      for (auto v : mesh.fv_range(mesh.face_handle(face))) {
        const Vec3& p = mesh.point(v);
        key[i++] = {p[0], p[1], p[2]};
      }
    std::sort(key.begin(), key.end());
    keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

/// The crossing face pairs of a run's result: their count, or none for a surface that lies over
/// itself throughout (lies_over_itself), whose crossings are neither counted nor untangled.
struct Crossings {
  std::optional<std::size_t> pairs;
  bool layered = false;
};

/// Returns the crossing face pairs of the mesh it leaves (find_self_intersections), which it knows
/// at every exit without another search. The last round returns after its untangling. A mesh that
/// lies over itself throughout is left as it is. Measured (one sphere of 20 faces 64 times at one
/// place, remeshed to [0.3, 0.5], 2 threads): the untangling took 4.3 of the run's 5.3 s, for
/// 753 832 crossing pairs it could not lower; 256 times, 21.9 of 28.5 s.
Crossings untangle_and_mend(TriMesh& mesh, const ReferenceSurface& reference, const Params& params,
                            std::vector<NeighbourCache>& caches, const CreaseGuard* creases, IterationStats& row,
                            PhaseSeconds& phases, std::stop_token stop) {
  // The row describes the mesh before the feature snap, which takes no edge out of the interval.
  const std::size_t outside_before = row.small + row.big;
  // The crossing pairs of the mesh, for the next round's untangling (which would search for them
  // again): first those the snap left, then those counted after a mend.
  std::optional<std::vector<std::pair<unsigned, unsigned>>> crossing;
  {
    PhaseTimer timer(phases.untangle);
    crossing = find_self_intersections_unless_layered(mesh, params.threads);
    if (!crossing) return {std::nullopt, true};
  }
  for (int round = 1;; ++round) {
    PhaseTimer timer(phases.untangle);
    const UntangleCounts u = untangle_creases_first(mesh, reference, params.e_min, params.e_max, params.threads,
                                                    creases, std::exchange(crossing, std::nullopt), stop);
    row.cleanup_fixes += u.moved;
    // Its flips and collapses count with the row's own, as the cleanup's do (count_cleanup).
    row.flips += u.flipped;
    row.collapses += u.collapsed;
    if (u.moved == 0 || round == kUntangleRounds || stop.stop_requested()) return {u.left.size()};
    // Nothing to mend when no more edges are outside than before (the vertex moves and flips
    // never take one out; a collapse may leave a short one, a flattened disk any).
    const IterationStats now = measure(mesh, params.e_min, params.e_max, params.threads);
    if (now.small + now.big <= outside_before) return {u.left.size()};
    const std::vector<CrossingKey> left = crossing_keys(mesh, u.left);
    timer.switch_to(phases.cleanup);
    const CleanupCounts c = run_cleanup(mesh, reference, params, caches, creases, /*final=*/true,
                                        /*boundary_only=*/false, stop);
    timer.switch_to(phases.untangle);
    count_cleanup(row, c);
    // Again only if the cleanup made faces cross that did not before (the pairs it left alone
    // keep their corners; its edits renumber the faces).
    if (fixes(c) == 0) return {u.left.size()};
    crossing = find_self_intersections(mesh, params.threads);
    const std::vector<CrossingKey> after = crossing_keys(mesh, *crossing);
    if (std::includes(left.begin(), left.end(), after.begin(), after.end())) return {after.size()};
  }
}

/// The statistics of `mesh` with the iteration number and operation counters of `counted`.
IterationStats measured_row(const TriMesh& mesh, const Params& params, const IterationStats& counted) {
  IterationStats row = measure(mesh, params.e_min, params.e_max, params.threads);
  row.iteration = counted.iteration;
  row.splits = counted.splits;
  row.collapses = counted.collapses;
  row.flips = counted.flips;
  row.cleanup_fixes = counted.cleanup_fixes;
  row.max_projection_distance = counted.max_projection_distance;
  return row;
}

/// The mesh's own normals (MeshTraits' vertex and face normal attributes) are not read while
/// remeshing: every step computes the normals it needs from the positions (geometry.h). Released
/// for the run, they cost nothing in the splits and garbage collections, and the returned mesh gets
/// them recomputed (they were stale before: permuted, zero at new vertices). Measured (CLI, the
/// Table 4.2 setup): armadillo's peak 110.9 -> 101.3 MB, the same time and the same mesh.
void release_normals(TriMesh& mesh) {
  mesh.release_vertex_normals();
  mesh.release_face_normals();
}

/// `mesh` becomes the snapshot's mesh again, without the normal attributes (release_normals).
void restore_snapshot(TriMesh& mesh, const MeshSnapshot& snapshot) {
  snapshot.rebuild(mesh);
  release_normals(mesh);
}

/// The mesh's elements numbered in space order (spatial_order.h), each vertex's neighbour cache
/// moved with it (in place, cycle by cycle, each cache copied once: a second vector of caches would
/// add 200 bytes a vertex to the run's peak); the normal attributes released again (release_normals).
void order_in_space(TriMesh& mesh, std::vector<NeighbourCache>& caches, unsigned threads) {
  const std::vector<unsigned> order = spatial_order(mesh, threads);
  release_normals(mesh);
  if (caches.empty()) return;
  const std::size_t n = order.size();
  caches.resize(n);
  std::vector<unsigned> from(n);  // the old index of the vertex now at each index
  for (std::size_t v = 0; v < n; ++v) from[order[v]] = static_cast<unsigned>(v);
  for (std::size_t start = 0; start < n; ++start) {
    if (from[start] == start) continue;
    // Pull each cache of the cycle through `start` into place; the first goes last.
    const NeighbourCache first = caches[start];
    std::size_t at = start;
    for (std::size_t source = from[at]; source != start; at = source, source = from[at]) {
      caches[at] = caches[source];
      from[at] = static_cast<unsigned>(at);
    }
    caches[at] = first;
    from[at] = static_cast<unsigned>(at);
  }
}

}  // namespace

std::string describe_phases(const PhaseSeconds& phases, double seconds) {
  std::string text;
  char buffer[64];
  for (const PhaseField& f : kPhaseFields) {
    std::snprintf(buffer, sizeof buffer, "%s %.3f, ", f.name, phases.*f.seconds);
    text += buffer;
  }
  std::snprintf(buffer, sizeof buffer, "other %.3f", other_seconds(phases, seconds));
  return text + buffer;
}

const char* outcome_name(Outcome o) {
  switch (o) {
    case Outcome::Converged: return "converged";
    case Outcome::Stalled: return "stalled";
    case Outcome::Cancelled: return "cancelled";
    case Outcome::Completed: break;
  }
  return "completed";
}

/// See crease_spacing() (equalize.h).
constexpr double kMinCreaseSpacing = 0.25;

double crease_spacing(const Params& params) {
  return std::max(params.e_min, kMinCreaseSpacing * 0.5 * (params.e_min + params.e_max));
}

namespace {

/// One run of equalize(): the mesh, its parameters (as_run's), its reference surface and caches,
/// and the state the iterations share, with one method per step of an iteration.
class Run final : private RunMesh {
 public:
  /// The setup: garbage collected, normals released, a large mesh numbered in space order, the
  /// reference surface, its feature points and creases taken from the input.
  Run(TriMesh& mesh, const Params& params, const OnIteration& on_iteration, std::stop_token stop);

  void relax_reference();
  void stellar_step(IterationStats& counters);
  void flip_step(IterationStats& counters);
  /// Returns false when stopped after the filter (its folds undone; no projection).
  bool move_step(int i, IterationStats& counters);
  void cleanup_step(int i, IterationStats& counters);
  /// The statistics row of iteration i: the mesh measured, with the iteration's counters.
  IterationStats statistics(int i, IterationStats counters) const;
  StoppingRule::Verdict judge(int i, IterationStats& row) { return stopping_.judge(i, row, cleanup_started_); }
  void ending_steps(IterationStats& row);
  /// Reports the row (StoppingRule::report) and returns the run's outcome after this iteration
  /// (Completed: it goes on).
  Outcome report(IterationStats& row, const StoppingRule::Verdict& verdict, Clock::time_point iteration_start);
  /// The result of a run that ended with `outcome` (the mesh's normals recomputed).
  Result finish(Outcome outcome);

 private:
  void take_reference();

  MeshSnapshot snapshot() const override { return MeshSnapshot(mesh_); }
  void restore(const MeshSnapshot& snapshot) override { restore_snapshot(mesh_, snapshot); }
  IterationStats measured(const IterationStats& counted) const override {
    return measured_row(mesh_, params_, counted);
  }
  std::size_t final_cleanup(IterationStats& row) override;

  const Clock::time_point start_ = Clock::now();
  TriMesh& mesh_;
  const Params params_;
  std::stop_token stop_;
  const double m_ = 0.5 * (params_.e_min + params_.e_max);
  const double sigma_ = main_phase_sigma(params_);
  Result result_;
  PhaseSeconds& phases_ = result_.phases;
  std::vector<NeighbourCache> caches_;   // per vertex, for the projection (projection.h)
  std::size_t renumbered_since_ = 0;     // splits and collapses since (kOrderShare)
  double on_crease_ = 0;                 // crease_tolerance
  std::unique_ptr<ReferenceSurface> reference_;
  std::unique_ptr<FeatureSnap> features_;
  std::unique_ptr<CreaseLines> creases_;
  std::unique_ptr<CreaseGuard> guard_;   // with Params::keep_creases
  PatchRest patch_rest_;                 // the per-iteration cleanups' memory of failed patch relaxations
  std::vector<IterationStats> history_;  // the row of each iteration (plateaued)
  bool cleanup_started_ = false;         // the full cleanup, once started, runs in every iteration
  int cleanup_from_ = 0;                 // the iteration it started in (0: not yet)
  StoppingRule stopping_;
};

}  // namespace

Result equalize(TriMesh& mesh, const Params& requested, const OnIteration& on_iteration, std::stop_token stop) {
  check_preconditions(mesh, requested);
  const Params params = as_run(mesh, requested);
  Run run(mesh, params, on_iteration, stop);
  for (int i = 1; i <= params.iterations; ++i) {
    if (stop.stop_requested()) return run.finish(Outcome::Cancelled);
    const auto iteration_start = Clock::now();
    IterationStats counters;  // this iteration's splits, collapses, flips, cleanup fixes
    if (params.relax_every > 0 && i % params.relax_every == 0) run.relax_reference();
    run.stellar_step(counters);  // Algorithms 2 and 3, on the priority list
    if (stop.stop_requested()) return run.finish(Outcome::Cancelled);
    run.flip_step(counters);  // Algorithm 4
    if (stop.stop_requested()) return run.finish(Outcome::Cancelled);
    if (!run.move_step(i, counters)) return run.finish(Outcome::Cancelled);  // Algorithms 5 and 6
    run.cleanup_step(i, counters);
    IterationStats row = run.statistics(i, counters);
    const StoppingRule::Verdict verdict = run.judge(i, row);  // converged, stalled, n reached?
    if (verdict.ending && params.cleanup && !stop.stop_requested()) run.ending_steps(row);
    const Outcome outcome = run.report(row, verdict, iteration_start);
    if (outcome != Outcome::Completed) return run.finish(outcome);
  }
  return run.finish(Outcome::Completed);
}

namespace {

Run::Run(TriMesh& mesh, const Params& params, const OnIteration& on_iteration, std::stop_token stop)
    : mesh_(mesh),
      params_(params),
      stop_(std::move(stop)),
      patch_rest_(mesh),
      stopping_(*this, params_, on_iteration, stop_) {
  const PhaseTimer timer(phases_.setup);
  collect_garbage(mesh_);
  release_normals(mesh_);
  if (mesh_.n_vertices() >= kOrderMinVertices) order_in_space(mesh_, caches_, params_.threads);
  on_crease_ = crease_tolerance(mesh_);
  take_reference();
}

/// The reference surface, its feature points and creases, taken from the mesh as it is.
void Run::take_reference() {
  reference_ = std::make_unique<ReferenceSurface>(mesh_);
  features_ = std::make_unique<FeatureSnap>(mesh_, crease_spacing(params_));
  creases_ = std::make_unique<CreaseLines>(mesh_);
  // With Params::keep_creases, the rule that keeps them (crease_lines.h); none without creases.
  guard_ = !params_.keep_creases || creases_->empty() ? nullptr : std::make_unique<CreaseGuard>(*creases_, on_crease_);
}

/// Every pr iterations (Params::relax_every): the reference is the current mesh.
void Run::relax_reference() {
  const PhaseTimer timer(phases_.setup);
  take_reference();
}

/// Algorithms 2 and 3: stellar operations on the priority list.
void Run::stellar_step(IterationStats& counters) {
  const PhaseTimer timer(phases_.stellar);
  const unsigned threads = params_.threads;
  const double m_i = std::min(2.0 * mean_edge_length(mesh_, threads), m_);
  const double sigma_i = band_at(sigma_, m_i);
  const std::vector<unsigned> list = make_priority_list(mesh_, m_i, sigma_i, threads);
  std::vector<OpenMesh::VertexHandle> placed;
  const StellarCounts stellar = stellar_operations(mesh_, list, m_i, sigma_i, guard_.get(), &placed);
  // Not in the thesis: the points the splits and collapses chose on their edges (eq. 3.1) go
  // onto the reference now, not only after the filter (Algorithm 6). The fold guard puts a
  // vertex back where it was before the filter, which for a new vertex was on its edge's chord,
  // under the surface; a vertex the guard held stayed there, iteration after iteration (cow
  // refined: vertices up to 0.62 units off the surface in every iteration from the 14th, 0.33
  // in the returned mesh; after this, 0.06 in the iterations). Before the flips, which see the
  // projected points: after them, the Hausdorff distances came out between and cheese's
  // simplification crossed more. Measured: bench/HISTORY.md, "Vertices kept on the surface".
  project_vertices(mesh_, placed, *reference_, threads, &caches_);
  collect_garbage(mesh_);
  renumbered_since_ += stellar.splits + stellar.collapses;
  if (mesh_.n_vertices() >= kOrderMinVertices &&
      static_cast<double>(renumbered_since_) >= kOrderShare * static_cast<double>(mesh_.n_vertices())) {
    order_in_space(mesh_, caches_, threads);
    renumbered_since_ = 0;
  }
  counters.splits = stellar.splits;
  counters.collapses = stellar.collapses;
}

/// Algorithm 4: valence-improving flips.
void Run::flip_step(IterationStats& counters) {
  const PhaseTimer timer(phases_.flips);
  counters.flips = valence_flips(mesh_, params_.flip_factor, kFlipSweeps, params_.threads, guard_.get());
  // Not in the thesis: the look-ahead flips that let 5-7 pairs cancel (regularize.h).
  if (params_.cleanup) {
    const RegularizeCounts r = regularize(mesh_, params_.flip_factor, kRegularizeSweeps, params_.threads,
                                          guard_.get(), params_.more_regular ? 2 : 1);
    counters.flips += r.single + r.chain_flips;
  }
}

/// Algorithm 5 then 6: filter and projection, guarded against folds as one move (not in the
/// thesis: fold_guard.h).
bool Run::move_step(int i, IterationStats& counters) {
  const unsigned threads = params_.threads;
  PhaseTimer timer(phases_.filter);
  const std::vector<Vec3> before = snapshot_points(mesh_);
  // Not in the thesis: until the cleanup starts (and in the first half of the iterations with the
  // cleanup off), vertices on the reference's creases move along them only (crease_lines.h). The
  // creases are lost, if at all, in the first iterations, while the mesh is coarse and the filter's
  // moves are long; held in every iteration they cost freedom: cheese's refinement had 34 crossing
  // face pairs over the five intervals of bench --spread (0 at [1.2, 1.8]) where it has 7 without
  // the rule and 10 with it held until the cleanup.
  const bool hold_creases = guard_ || (cleanup_from_ == 0 && 2 * i <= params_.iterations);
  low_pass_filter(mesh_, params_.rings, threads, hold_creases ? creases_.get() : nullptr, on_crease_);
  if (stop_.stop_requested()) {
    timer.switch_to(phases_.guards);
    undo_folds(mesh_, before, threads);
    return false;
  }
  timer.switch_to(phases_.projection);
  counters.max_projection_distance = project_onto_reference(mesh_, *reference_, threads, &caches_);
  timer.switch_to(phases_.guards);
  undo_folds(mesh_, before, threads);
  // Not in the thesis: once the interval cleanup has run for kSteadyAfter iterations, the filter
  // and projection may not take an edge out of the interval (nor fold a face, as before), while
  // the run keeps reaching new lows of edges outside (kExploreAfter) and has not converged.
  if (params_.cleanup && cleanup_from_ > 0 && i - cleanup_from_ >= kSteadyAfter && !stopping_.polishing() &&
      i - 1 - stopping_.last_low() < kExploreAfter)
    while (undo_interval_breaks(mesh_, before, params_.e_min, params_.e_max, 3, reference_.get(), &caches_) > 0 &&
           undo_folds(mesh_, before, threads) > 0) {
    }
  return true;
}

/// Not in the thesis: the post-process its conclusion asks for (interval_cleanup.h). It runs in
/// the last iteration, and in every iteration once at least kCleanupFrom of the edges are inside,
/// the main phase has plateaued or half the iterations are done, so that a run reaches every edge
/// inside and stops early (convergence) instead of wandering around 99.6 % (or, when
/// simplifying, around 88 %).
/// On open meshes its boundary part runs every iteration (see interval_cleanup.h).
void Run::cleanup_step(int i, IterationStats& counters) {
  if (!params_.cleanup || stop_.stop_requested()) return;
  const bool last = i == params_.iterations;
  cleanup_started_ = cleanup_started_ || 2 * i > params_.iterations || plateaued(history_) ||
                     inside_fraction(mesh_, params_, params_.threads) >= kCleanupFrom;
  if (cleanup_started_ && cleanup_from_ == 0) cleanup_from_ = i;
  const bool full = last || cleanup_started_;
  if (!full && !reference_->has_boundary()) return;
  const PhaseTimer timer(phases_.cleanup);
  const CleanupCounts c = run_cleanup(mesh_, *reference_, params_, caches_, guard_.get(), /*final=*/false,
                                      /*boundary_only=*/!full, stop_, &patch_rest_);
  count_cleanup(counters, c);
  renumbered_since_ += c.splits + c.collapses;
}

IterationStats Run::statistics(int i, IterationStats counters) const {
  counters.iteration = i;
  return measured_row(mesh_, params_, counters);
}

/// Not in the thesis: before the mesh is returned, the reference vertices it cuts off (tips,
/// creases) are put back on it (feature_snap.h); no edge leaves the interval. Then faces that cross
/// each other are moved apart (untangle_and_mend).
void Run::ending_steps(IterationStats& row) {
  // The neighbour caches are done with (the snap's relaxations keep their own; a mending
  // cleanup after the untangling goes without, exact either way): freed before the snap
  // builds its index of the mesh, they no longer add to the run's peak (nefertiti: 28 of
  // its 119 MB there).
  std::vector<NeighbourCache>().swap(caches_);
  PhaseTimer timer(phases_.snap);
  const std::size_t snapped =
      features_->apply(mesh_, *reference_, params_.e_min, params_.e_max, params_.threads, guard_.get());
  timer.stop();
  const std::size_t fixes_before = row.cleanup_fixes;
  row.cleanup_fixes += snapped;
  const Crossings crossings =
      untangle_and_mend(mesh_, *reference_, params_, caches_, guard_.get(), row, phases_, stop_);
  result_.crossing_pairs = crossings.pairs;
  result_.layered = crossings.layered;
  if (row.cleanup_fixes != fixes_before) row = measured_row(mesh_, params_, row);
}

Outcome Run::report(IterationStats& row, const StoppingRule::Verdict& verdict, Clock::time_point iteration_start) {
  // Taken before the row is reported: a stop that on_iteration asks for is seen at the next
  // iteration's start, so the run ends with the iterations it reported.
  const Outcome outcome = stopping_.outcome(verdict, row);
  row.seconds = verdict.restored ? stopping_.best_row().seconds : seconds_since(iteration_start);
  result_.iterations_done = row.iteration;
  history_.push_back(row);
  stopping_.report(row, verdict.ending);
  return outcome;
}

std::size_t Run::final_cleanup(IterationStats& row) {
  PhaseTimer timer(phases_.cleanup);
  const CleanupCounts c = run_cleanup(mesh_, *reference_, params_, caches_, guard_.get(), /*final=*/true,
                                      /*boundary_only=*/false, stop_);
  timer.stop();
  count_cleanup(row, c);
  return fixes(c);
}

Result Run::finish(Outcome outcome) {
  result_.outcome = outcome;
  stopping_.flush();
  mesh_.request_vertex_normals();
  mesh_.request_face_normals();
  mesh_.update_normals();
  const bool cancelled = outcome == Outcome::Cancelled;
  // Measured for the result only: a cancelled run has none (and its caller is waiting).
  if (!cancelled)
    result_.thin = thin_parts(mesh_, *reference_, params_.e_min, params_.e_max, params_.threads, guard_.get());
  // A run without the untangling (cleanup off, or stopped before it) counts them here; a cancelled
  // one leaves them unknown.
  if (!result_.crossing_pairs && !result_.layered && !cancelled) {
    const auto crossing = find_self_intersections_unless_layered(mesh_, params_.threads);
    result_.layered = !crossing;
    if (crossing) result_.crossing_pairs = crossing->size();
  }
  if (!cancelled) result_.triangles = triangle_quality(mesh_);
  result_.seconds = seconds_since(start_);
  return result_;
}

}  // namespace

}  // namespace remesh
