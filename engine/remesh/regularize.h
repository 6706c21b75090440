#pragma once
/// \file regularize.h
/// Not in the thesis: valence flips that look one flip ahead. Most irregular vertices of a remeshed
/// surface sit in 5-7 pairs (dislocations of the hexagonal lattice); a pair moves by one flip, but
/// that flip leaves the valence deviation of Algorithm 4 unchanged, so Algorithm 4 never makes it
/// and pairs that could cancel stay where they are. This step makes such a neutral flip when a
/// second flip at one of its quad's corners then lowers the deviation: each pair of flips lowers
/// the deviation strictly, so sweeps cannot cycle. Every flip passes Algorithm 4's angle rule with
/// factor f and its safety checks (flip_is_safe).
///
/// It runs after Algorithm 4 in every iteration (Params::cleanup). Measured in the Table 4.2 setup
/// (bench_equalize): regular vertices 85-87 % -> 88-91 % on spot, bunny, fandisk, kitten and cow,
/// and the runs converge in fewer iterations.

#include <cstddef>

#include "core/mesh.h"
#include "remesh/crease_lines.h"

namespace remesh {

struct RegularizeCounts {
  std::size_t single = 0;  ///< flips that lower the deviation alone
  std::size_t pairs = 0;   ///< pairs of flips (a neutral one, then one that lowers the deviation)
};

/// Sweeps over the interior edges (in index order) while they flip something, at most `max_sweeps`.
/// `threads` count the valences; the sweeps are serial.
/// With `creases`, an edge along a crease is not flipped (flip_is_safe).
RegularizeCounts regularize(TriMesh& mesh, double f, int max_sweeps = 4, unsigned threads = 1,
                            const CreaseGuard* creases = nullptr);

}  // namespace remesh
