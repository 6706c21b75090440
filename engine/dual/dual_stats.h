#pragma once
/// \file dual_stats.h
/// Not in the thesis: the dual as an atom lattice (carbon: one atom per dual vertex, one bond per
/// dual edge). What a user of it asks: how many atoms and bonds, how many rings of each size (a
/// closed surface of genus 0 has sum (6 - k) n_k = 12 over its k-sided rings: with rings of 5, 6
/// and 7 sides only, 12 more pentagons than heptagons), and how long the bonds are.
/// For equilateral triangles of side a the dual edge is a / sqrt(3) (ALGORITHM.md), so the bonds
/// of a primal run in [e_min, e_max] are judged against [e_min, e_max] / sqrt(3).

#include <cmath>
#include <cstddef>
#include <map>

#include "core/mesh.h"

namespace remesh {

/// The primal edge length whose equilateral triangles have dual edges (bonds) of length `bond`:
/// bond * sqrt(3). A bond interval [b_min, b_max] asks for edges in [b_min, b_max] * sqrt(3).
inline double edge_for_bond(double bond) { return bond * std::sqrt(3.0); }
/// The dual edge (bond) of equilateral triangles of side `edge`: edge / sqrt(3), to 15 significant
/// digits. A bond interval comes back as given: bond * sqrt(3) / sqrt(3) in doubles is not always
/// the bond (1.278 gave 1.2779999999999998, about one bond in ten), and 15 digits are exact for
/// every decimal of up to 15 digits; they change any other value by at most about 5e-15 of it
/// (half a unit of the 15th digit, and the rounding to the nearest double).
double bond_for_edge(double edge);

struct DualStats {
  std::size_t atoms = 0;  ///< dual vertices
  std::size_t bonds = 0;  ///< dual edges
  /// Dual faces by their number of sides (5: pentagons, 6: hexagons, 7: heptagons, ...).
  std::map<std::size_t, std::size_t> rings;
  /// Bond lengths: mean, population standard deviation, smallest, largest (0 without bonds).
  double mean = 0, deviation = 0, min = 0, max = 0;
  /// The bond interval [e_min, e_max] / sqrt(3), and the bonds below and above it (0, 0 and 0, 0
  /// when no interval was given).
  double bond_min = 0, bond_max = 0;
  std::size_t short_bonds = 0, long_bonds = 0;
  /// Share of the bonds inside [bond_min, bond_max] (1 without bonds or interval).
  double inside_fraction() const {
    return bonds == 0 ? 1.0 : 1.0 - static_cast<double>(short_bonds + long_bonds) / static_cast<double>(bonds);
  }
};

/// The statistics of `dual` (a trivalent_dual() result). With 0 < e_min < e_max (the primal
/// interval), the bonds are also counted against [e_min, e_max] / sqrt(3).
DualStats dual_stats(const PolyMesh& dual, double e_min = 0, double e_max = 0);

}  // namespace remesh
