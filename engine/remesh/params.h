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
  bool run_all_iterations = false;  ///< false: stop early once every edge is inside [e_min, e_max]
  unsigned threads = 0;       ///< 0 = all cores; results do not depend on it
  int max_iterations = 1000;  ///< upper bound for `iterations` (the service lowers it)
  std::size_t max_output_faces = 20'000'000;  ///< refuse jobs whose estimated output exceeds it; 0 = no limit
  /// Not in the thesis: (1) fix the remaining edges outside [e_min, e_max] by local flips,
  /// collapses, splits, vertex and patch relocations (interval_cleanup.h), the post-process the
  /// thesis' conclusion asks for; (2) after Algorithm 4, the look-ahead flips that let 5-7 pairs
  /// cancel (regularize.h). false reproduces the thesis' method alone.
  bool cleanup = true;
};

/// Every invalid field, named as the API names it: "emin", "emax", "rings", "iterations",
/// "relax_every", "flip_factor", "threads". Empty when valid.
std::vector<FieldError> check(const Params& params);

}  // namespace remesh
