#pragma once
/// \file regularize.h
/// Not in the thesis: valence flips that look ahead. Most irregular vertices of a remeshed surface
/// sit in 5-7 pairs (dislocations of the hexagonal lattice); a pair moves by one flip, but that
/// flip leaves the valence deviation of Algorithm 4 unchanged, so Algorithm 4 never makes it and
/// pairs that could cancel stay where they are. This step makes a chain of such neutral flips, each
/// at a corner of the last, at most `depth` of them (one by default), when a flip at a corner of
/// the last one then lowers the deviation: each chain lowers the deviation strictly, so sweeps
/// cannot cycle. Every flip passes Algorithm 4's angle rule with factor f and its safety checks
/// (flip_is_safe). In chains that may be longer than one neutral flip, a neutral flip never makes
/// regular a valence-5 vertex whose angle deficit exceeds kConeDeficit (a cone: the tip of an ear,
/// a peak) nor a valence-7 vertex whose deficit is below -kConeDeficit (a saddle): there the defect
/// belongs to the surface's curvature, and moving it away lets the mesh cut the tip.
///
/// It runs after Algorithm 4 in every iteration (Params::cleanup), with depth 2 under
/// Params::more_regular. Measured in the Table 4.2 setup (bench_equalize): with one neutral flip,
/// regular vertices 85-87 % -> 88-91 % on spot, bunny, fandisk, kitten and cow, and the runs
/// converge in fewer iterations. Two: params.h (more_regular).

#include <cstddef>

#include "core/mesh.h"
#include "remesh/crease_lines.h"
#include "remesh/valence_flips.h"

namespace remesh {

struct RegularizeCounts {
  std::size_t single = 0;       ///< flips that lower the deviation alone
  std::size_t chains = 0;       ///< chains of flips (neutral ones, then one that lowers the deviation)
  std::size_t chain_flips = 0;  ///< the flips of those chains
};

/// The angle deficit (radians) from which a valence-5 vertex counts as a cone point (and, negated,
/// a valence-7 vertex as a saddle) that neutral flips leave irregular: 0.4, about 38 % of the pi / 3
/// a whole valence-5 defect carries in a lattice of equilateral triangles. Measured (bench --spread,
/// Table 4.2 setup, two neutral flips, largest distance to the input in % of the bbox diagonal, mean
/// of five; measured while the sweeps' walk still touched one ring, not two): without it -> with it,
/// kitten 0.33 -> 0.26 and cheese 3.0 -> 2.8, but bunny 0.62 -> 0.70; one neutral flip: kitten 0.22.
constexpr double kConeDeficit = 0.4;

/// The cone rule: may a neutral flip of q's interior edge (valences from `info`, current for `mesh`)
/// give its four vertices their new valences? False when it would make regular a valence-5 vertex
/// whose angle deficit exceeds kConeDeficit, or a valence-7 vertex whose deficit is below
/// -kConeDeficit.
bool cones_kept(const TriMesh& mesh, const VertexInfo& info, const Quad& q);

/// Sweeps over the interior edges (in index order) while they flip something, at most `max_sweeps`.
/// `threads` count the valences; the sweeps are serial. `depth`: neutral flips in a chain, at most
/// (1: a neutral flip and one that lowers the deviation).
/// With `creases`, an edge along a crease is not flipped (flip_is_safe).
RegularizeCounts regularize(TriMesh& mesh, double f, int max_sweeps = 4, unsigned threads = 1,
                            const CreaseGuard* creases = nullptr, int depth = 1);

}  // namespace remesh
