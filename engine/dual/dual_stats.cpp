#include "dual/dual_stats.h"

#include <algorithm>
#include <cmath>
#include <charconv>
#include <limits>

namespace remesh {

double bond_for_edge(double edge) {
  const double bond = edge / std::sqrt(3.0);
  if (!std::isfinite(bond)) return bond;
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, bond, std::chars_format::general, 15);
  double rounded = bond;
  std::from_chars(text, written.ptr, rounded);
  return rounded;
}

DualStats dual_stats(const PolyMesh& dual, double e_min, double e_max) {
  DualStats s;
  for (auto v : dual.vertices()) s.atoms += !dual.status(v).deleted();
  for (auto f : dual.faces())
    if (!dual.status(f).deleted()) ++s.rings[dual.valence(f)];
  const bool interval = e_min > 0 && e_max > e_min;
  if (interval) s.bond_min = bond_for_edge(e_min), s.bond_max = bond_for_edge(e_max);
  double sum = 0;
  s.min = std::numeric_limits<double>::infinity();
  for (auto e : dual.edges()) {
    if (dual.status(e).deleted()) continue;
    const double l = dual.calc_edge_length(e);
    ++s.bonds;
    sum += l;
    s.min = std::min(s.min, l);
    s.max = std::max(s.max, l);
    if (interval) s.short_bonds += l < s.bond_min, s.long_bonds += l > s.bond_max;
  }
  if (s.bonds == 0) {
    s.min = 0;
    return s;
  }
  const double n = static_cast<double>(s.bonds);
  s.mean = sum / n;
  // Two passes, as the primal statistics (statistics.cpp): no cancellation for long bonds.
  double dev2 = 0;
  for (auto e : dual.edges())
    if (!dual.status(e).deleted()) {
      const double d = dual.calc_edge_length(e) - s.mean;
      dev2 += d * d;
    }
  s.deviation = std::sqrt(dev2 / n);
  return s;
}

}  // namespace remesh
