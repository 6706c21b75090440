/// \file dual_stats_test.cpp
/// The dual's atom-lattice statistics (dual_stats.h) against the dual itself: counts, rings by
/// Euler's formula, bond lengths recomputed independently.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "dual/dual_stats.h"
#include "dual/trivalent_dual.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

struct Case {
  std::string name;
  TriMesh mesh;
  long euler;  ///< V - E + F of the (closed) primal, which the dual shares
};

std::vector<Case> closed_meshes() {
  return {{"icosphere", test::make_icosphere(3, 5.0), 2},
          {"torus", test::make_torus(24, 12, 4.0, 1.5), 0},
          {"double torus", test::make_double_torus(1.0, 2), -2}};
}

}  // namespace

TEST_CASE("dual_stats counts the atoms, bonds and rings of the dual, the rings obey Euler's formula", "[dual]") {
  for (const Case& c : closed_meshes()) {
    INFO(c.name);
    const PolyMesh dual = trivalent_dual(c.mesh);
    const DualStats s = dual_stats(dual);
    CHECK(s.atoms == c.mesh.n_faces());
    CHECK(s.bonds == c.mesh.n_edges());
    std::size_t faces = 0;
    long excess = 0;  // sum over the rings of (6 - sides): 6 (V - E + F) on a trivalent closed surface
    for (const auto& [sides, count] : s.rings) {
      faces += count;
      excess += (6 - static_cast<long>(sides)) * static_cast<long>(count);
    }
    CHECK(faces == c.mesh.n_vertices());
    CHECK(excess == 6 * c.euler);
  }
  // The icosphere's dual is a fullerene: 12 pentagons, every other ring a hexagon.
  const DualStats ico = dual_stats(trivalent_dual(test::make_icosphere(2)));
  CHECK(ico.rings.at(5) == 12);
  CHECK(ico.rings.size() == 2);
  CHECK(ico.rings.at(6) + 12 == test::make_icosphere(2).n_vertices());
}

TEST_CASE("dual_stats' bond lengths equal a recomputation, and the interval is the primal's over sqrt(3)", "[dual]") {
  for (const Case& c : closed_meshes()) {
    INFO(c.name);
    const PolyMesh dual = trivalent_dual(c.mesh);
    std::vector<double> lengths;
    for (auto e : dual.edges()) {
      const auto h = dual.halfedge_handle(e, 0);
      lengths.push_back((dual.point(dual.to_vertex_handle(h)) - dual.point(dual.from_vertex_handle(h))).norm());
    }
    std::sort(lengths.begin(), lengths.end());
    double mean = 0;
    for (double l : lengths) mean += l / static_cast<double>(lengths.size());
    double var = 0;
    for (double l : lengths) var += (l - mean) * (l - mean) / static_cast<double>(lengths.size());
    // An interval through the middle of the lengths: its bounds over sqrt(3) split them.
    const double lo = lengths[lengths.size() / 4], hi = lengths[3 * lengths.size() / 4];
    const double e_min = lo * std::sqrt(3.0), e_max = hi * std::sqrt(3.0);
    const DualStats s = dual_stats(dual, e_min, e_max);
    CHECK(s.mean == Approx(mean).epsilon(1e-12));
    CHECK(s.deviation == Approx(std::sqrt(var)).epsilon(1e-9));
    CHECK(s.min == lengths.front());
    CHECK(s.max == lengths.back());
    // To 15 significant digits (bond_for_edge).
    CHECK(s.bond_min == Approx(lo).epsilon(1e-14));
    CHECK(s.bond_max == Approx(hi).epsilon(1e-14));
    const auto below = std::count_if(lengths.begin(), lengths.end(), [&](double l) { return l < s.bond_min; });
    const auto above = std::count_if(lengths.begin(), lengths.end(), [&](double l) { return l > s.bond_max; });
    CHECK(s.short_bonds == static_cast<std::size_t>(below));
    CHECK(s.long_bonds == static_cast<std::size_t>(above));
    CHECK(s.short_bonds > 0);
    CHECK(s.long_bonds > 0);
    CHECK(s.inside_fraction() == Approx(1.0 - static_cast<double>(below + above) / lengths.size()));
  }
  // Without an interval nothing is counted outside.
  const DualStats none = dual_stats(trivalent_dual(test::make_torus(24, 12, 4.0, 1.5)));
  CHECK(none.short_bonds + none.long_bonds == 0);
  CHECK(none.inside_fraction() == 1.0);
}

TEST_CASE("dual_stats: equilateral triangles of side a have bonds of a / sqrt(3)", "[dual]") {
  // A flat lattice of equilateral triangles (side 1.5): the interior bonds join centroids of
  // neighbouring triangles, a / sqrt(3) apart. Bonds at the rim join triangles too, the same way.
  const TriMesh lattice = test::make_hex_lattice_patch(12, 12, 1.5);
  const DualStats s = dual_stats(trivalent_dual(lattice), 1.5 * 0.99, 1.5 * 1.01);
  REQUIRE(s.bonds > 100);
  CHECK(s.mean == Approx(1.5 / std::sqrt(3.0)).epsilon(1e-9));
  CHECK(s.deviation < 1e-9);
  CHECK(s.short_bonds + s.long_bonds == 0);
  CHECK(s.rings.at(6) > 0);
  // An interval just above: every bond is short.
  const DualStats above = dual_stats(trivalent_dual(lattice), 1.5 * 1.01, 1.5 * 1.1);
  CHECK(above.short_bonds == above.bonds);
  CHECK(above.inside_fraction() == 0.0);
}

TEST_CASE("bond_for_edge gives back the bond that edge_for_bond was given", "[dual]") {
  // Bonds as users type them (carbon's 1.42 angstrom +- 10 %, boron nitride's 1.45, ...): each
  // comes back exactly, so the job's dual.bond_interval reads as given. Plain division by sqrt(3)
  // gave 1.2779999999999998 for 1.278.
  int plain_misses = 0;
  for (double bond : {1.278, 1.562, 1.42, 1.45, 1.3, 1.5, 0.1, 0.35, 2.5, 3.1415926535, 123.456, 1e-3, 7e5}) {
    INFO(bond);
    CHECK(bond_for_edge(edge_for_bond(bond)) == bond);
    plain_misses += edge_for_bond(bond) / std::sqrt(3.0) != bond;
  }
  CHECK(plain_misses > 0);  // the case this guards against occurs among them
  // Any other value moves by at most about 5e-15 of itself (half a unit of the 15th digit, plus
  // the last bit); non-finite and zero pass through.
  for (double edge : {1.0, 2.0 / 3.0, std::sqrt(2.0), 1e-300, 1e300, 0.0}) {
    INFO(edge);
    const double exact = edge / std::sqrt(3.0);
    CHECK(std::abs(bond_for_edge(edge) - exact) <= (5e-15 + 0x1p-52) * exact);
  }
  CHECK(std::isinf(bond_for_edge(std::numeric_limits<double>::infinity())));
  CHECK(std::isnan(bond_for_edge(std::nan(""))));
}
