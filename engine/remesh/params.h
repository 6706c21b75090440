#pragma once
/// \file params.h
/// The thesis' tuple (e_min, e_max, k, n, pr, f) and the product's additions, with validation.

#include <cstddef>
#include <vector>

#include "core/errors.h"

namespace remesh {

struct Params {
  double e_min = 0;           ///< smallest allowed edge length, > 0 (required)
  double e_max = 0;           ///< largest allowed edge length, > e_min (required)
  int rings = 2;              ///< k: rings of the low-pass filter, 1..4
  int iterations = 100;       ///< n: iterations, 1..max_iterations
  int relax_every = 0;        ///< pr: replace the reference by the current mesh every pr iterations; 0 = never
  double flip_factor = 0.5;   ///< f: a flip may lower the min angle to no less than f * old, 0..1
  /// false: stop early once every edge is inside [e_min, e_max] (converged) or the count outside stops
  /// falling (stalled). true: run all n iterations, the cleanup in the same ones, and return the mesh
  /// of the run's low (the fewest edges outside, then the most regular vertices) after the final
  /// cleanup, as a run that reaches n does; the outcome is Completed.
  bool run_all_iterations = false;
  unsigned threads = 0;       ///< 0 = all cores; results do not depend on it
  int max_iterations = 1000;  ///< upper bound for `iterations` (the service lowers it)
  std::size_t max_output_faces = 20'000'000;  ///< refuse jobs whose estimated output exceeds it; 0 = no limit
  /// Not in the thesis: (1) fix the remaining edges outside [e_min, e_max] by local flips,
  /// collapses, splits, vertex and patch relocations (interval_cleanup.h), the post-process the
  /// thesis' conclusion asks for; (2) after Algorithm 4, the look-ahead flips that let 5-7 pairs
  /// cancel (regularize.h). With it go the filter's interval guard (kSteadyAfter), the feature
  /// snap and the untangling (equalize.cpp), the polishing and the return of the best mesh
  /// (kPolishMax) and the stall stop (stopping_rule.h). false is not the thesis' method alone: the
  /// additions inside its steps stay (the collapse length limit and tips kept by collapses,
  /// stellar_operations.h; corners held by the filter, low_pass_filter.h; three flip sweeps; the
  /// fold guard, fold_guard.h; placed points projected at once; boundary vertices projected onto
  /// the boundary curves, projection.h; creases followed in the first half of the iterations,
  /// crease_lines.h).
  bool cleanup = true;
  /// Not in the thesis: the interval cleanup keeps tips (is_tip in stellar_operations.h: ears,
  /// horns, spikes) where they are, as the stellar operations always do: none of its collapses,
  /// relocations or patch relaxations moves them. The surface stays closer to the input there, and
  /// where the input is thinner than the interval allows more edges stay outside. Measured (five
  /// intervals around [1.2, 1.8], Table 4.2 meshes; mean Hausdorff % of the bbox diagonal, mean %
  /// inside): cheese refinement 3.70 -> 2.51 and 99.57 -> 98.82, cow 1.41 -> 1.06 and 99.96 ->
  /// 99.70, cow simplification 2.93 -> 1.78 and 93.6 -> 92.3, spot simplification 2.14 -> 1.61 and
  /// 100 % either way.
  bool protect_tips = false;
  /// Not in the thesis: the reference's creases (crease_lines.h: edges over 75 degrees, in lines
  /// of 10 or more) stay in the surface exactly, as its boundary does (CreaseGuard): vertices on
  /// them move along them only, their edges are not flipped, splits and collapses put their
  /// vertex on them, and an edge between two creases is not collapsed; the untangling follows the
  /// rule too, and breaks it only for the crossings it cannot mend otherwise. For CAD models; off, a
  /// vertex on a crease slides along it only until the interval cleanup starts, and the creases
  /// come out slightly bevelled. Measured (Table 4.2 setup, means over the five intervals of bench
  /// --spread; inside %, Hausdorff % of the bbox diagonal, off -> on): fandisk refined 100 / 0.533
  /// -> 99.969 / 0.250, simplified 100 / 1.704 -> 99.492 / 0.770; cheese refined 99.66 / 2.88 ->
  /// 95.81 / 1.55 (its hole rims have corners closer together than e_min, and walls thinner than
  /// e_min between two creases: a third of the edges left outside are short edges between crease
  /// points, which no collapse may merge), cow refined 99.91 / 1.19 -> 99.79 / 1.27.
  bool keep_creases = false;
  /// Not in the thesis: the look-ahead flips (regularize.h, with `cleanup`) make chains of up to two
  /// neutral flips instead of one, for more valence-6 vertices (hexagons in the dual). Measured
  /// (Table 4.2 setup, means over the five intervals of bench --spread, off -> on): regular vertices
  /// 1.4-2.1 points more on the 11 shared meshes but cheese (cow 88.1 -> 89.9 %, nefertiti 89.7 ->
  /// 91.6 %); the largest distance to the input 4 % lower (camelhead) to 37 % higher (at ear tips
  /// and peaks: bunny 0.62 -> 0.67, mountain 0.15 -> 0.20 % of the bbox diagonal); -2 to +45 % time
  /// (cow the most).
  bool more_regular = false;
  /// Not in the thesis, and not used by equalize(): whoever builds the result's trivalent dual
  /// (the CLI's --dual, the service) relaxes its bonds toward the middle of [e_min, e_max] / sqrt(3)
  /// (dual/relax_bonds.h), instead of leaving each dual vertex at its triangle's centroid.
  bool relax_dual = false;
};

/// Every invalid field, named as the API names it: "emin", "emax", "rings", "iterations",
/// "relax_every", "flip_factor", "threads". Empty when valid.
std::vector<FieldError> check(const Params& params);

}  // namespace remesh
