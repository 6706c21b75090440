#pragma once
/// \file relax_bonds.h
/// Not in the thesis: the dual's bonds relaxed toward one length. The dual vertex of a triangle is
/// its centroid (ALGORITHM.md), so a bond depends on the shapes of two triangles and the bonds
/// spread more than the edges: spot remeshed at [2.21, 2.71] (bonds of 1.42 +- 10 %) has 91 % of
/// its edges but 83 % of its bonds inside the bond interval. A user who builds an atom lattice
/// from the dual wants the bonds themselves in it.
///
/// Springs along the bonds, rest length the middle of [bond_min, bond_max]: every dual vertex with
/// three bonds moves (all at once, half way) toward the mean of the points at rest length from its
/// neighbours, along the surface only (the normal part of the move dropped), then onto the
/// reference surface. A move that turns a dual face over (its normal against what it was) is
/// undone. Dual vertices on the dual's boundary (an open mesh's) stay; a move is at most half the
/// rest length. The
/// iterations stop once every bond is inside, or after kPatience without a new high of bonds
/// inside; the positions with the most bonds inside are kept.
/// Two bonded atoms in one place (the projection of the centroids can put the three around a
/// valence-3 vertex on one corner of a thin part: cheese at its mean edge +- 10 % has three such
/// bonds) are pushed apart along the direction to the atom's other neighbours, and where the
/// projection would put them back in one place they stay off the surface by their short move.

#include <cstddef>
#include <stop_token>

#include "core/mesh.h"

namespace remesh {

class ReferenceSurface;

struct BondRelaxation {
  int iterations = 0;               ///< iterations run
  std::size_t inside_before = 0;    ///< bonds inside [bond_min, bond_max] before
  std::size_t inside_after = 0;     ///< and after (never fewer)
  std::size_t bonds = 0;
  double seconds = 0;               ///< time spent
};

/// Relaxes the bonds of `dual` (a trivalent_dual() result) toward the middle of the bond interval
/// [e_min, e_max] / sqrt(3) (the primal interval, as dual_stats() takes it; the rest length kept
/// within 0.8-1.25 times the mean bond, for an interval open upward), its vertices kept on
/// `reference`. At most `max_iterations`; a stop request ends it after the current iteration, with
/// the best positions so far. Deterministic whatever `threads`. The counts are dual_stats()'s.
/// \pre 0 < e_min < e_max.
BondRelaxation relax_bonds(PolyMesh& dual, double e_min, double e_max, const ReferenceSurface& reference,
                           unsigned threads = 0, std::stop_token stop = {}, int max_iterations = 60);

}  // namespace remesh
