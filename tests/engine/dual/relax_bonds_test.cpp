/// \file relax_bonds_test.cpp
/// The dual's bonds relaxed toward the middle of the bond interval (dual/relax_bonds.h), on a
/// remeshed sphere and torus.

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "dual/relax_bonds.h"
#include "dual/trivalent_dual.h"
#include "remesh/equalize.h"
#include "remesh/reference_surface.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

double mean_edge(const TriMesh& m) {
  double sum = 0;
  for (auto e : m.edges()) sum += m.calc_edge_length(e);
  return sum / static_cast<double>(m.n_edges());
}

std::size_t bonds_inside(const PolyMesh& d, double lo, double hi) {
  std::size_t n = 0;
  for (auto e : d.edges()) {
    const double l = d.calc_edge_length(e);
    n += l >= lo && l <= hi;
  }
  return n;
}

/// Newell's normal of a dual face.
Vec3 polygon_normal(const PolyMesh& d, OpenMesh::FaceHandle f) {
  Vec3 n(0, 0, 0);
  for (auto h : d.fh_range(f)) n += OpenMesh::cross(d.point(d.from_vertex_handle(h)), d.point(d.to_vertex_handle(h)));
  return n;
}

struct Surface {
  const char* name;
  TriMesh input;
  /// Distance from p to the smooth surface the input approximates, and its outward direction at p.
  double (*distance)(const Vec3&);
  Vec3 (*outward)(const Vec3&);
};

constexpr double kRadius = 10, kMajor = 12, kMinor = 4;
/// The primal interval a bond interval comes from is sqrt(3) times as long (relax_bonds takes it).
const double kRoot3 = std::sqrt(3.0);

}  // namespace

TEST_CASE("relaxed bonds: more inside the interval, on the surface, no face turned over", "[dual]") {
  const std::vector<Surface> surfaces = {
      {"sphere", test::make_icosphere(4, kRadius), [](const Vec3& p) { return std::abs(p.norm() - kRadius); },
       [](const Vec3& p) { return p; }},
      {"torus", test::make_torus(96, 40, kMajor, kMinor),
       [](const Vec3& p) {
         const double ring = std::hypot(p[0], p[1]) - kMajor;
         return std::abs(std::hypot(ring, p[2]) - kMinor);
       },
       [](const Vec3& p) {
         const double rho = std::hypot(p[0], p[1]);
         return Vec3(p[0] - kMajor * p[0] / rho, p[1] - kMajor * p[1] / rho, p[2]);
       }},
  };
  for (const Surface& s : surfaces) {
    INFO(s.name);
    // A tight interval (bonds of 1 +- 10 %), a little coarser than the input.
    const double length = 1.3 * mean_edge(s.input);
    Params p;
    p.e_min = 0.9 * length;
    p.e_max = 1.1 * length;
    TriMesh mesh = s.input;
    equalize(mesh, p);
    const ReferenceSurface reference(s.input);
    const PolyMesh centroids = trivalent_dual(mesh, &reference);
    const double lo = p.e_min / std::sqrt(3.0), hi = p.e_max / std::sqrt(3.0);
    PolyMesh relaxed = centroids;
    const BondRelaxation r = relax_bonds(relaxed, p.e_min, p.e_max, reference, 1);

    const std::size_t before = bonds_inside(centroids, lo, hi), after = bonds_inside(relaxed, lo, hi);
    INFO("bonds inside " << before << " -> " << after << " of " << relaxed.n_edges() << " in " << r.iterations
                         << " iterations");
    CHECK(r.inside_before == before);
    CHECK(r.inside_after == after);
    CHECK(r.bonds == relaxed.n_edges());
    CHECK(after >= before + relaxed.n_edges() / 20);  // at least 5 points more
    CHECK(after >= relaxed.n_edges() * 97 / 100);

    // The same lattice: counts, and three bonds at every atom of a closed surface.
    CHECK(relaxed.n_vertices() == centroids.n_vertices());
    CHECK(relaxed.n_edges() == centroids.n_edges());
    CHECK(relaxed.n_faces() == centroids.n_faces());
    for (auto v : relaxed.vertices()) CHECK(relaxed.valence(v) == 3);
    // On the reference (within its chords' sag of the smooth surface), every ring facing outward.
    double farthest = 0;
    for (auto v : relaxed.vertices()) farthest = std::max(farthest, s.distance(relaxed.point(v)));
    CHECK(farthest < 0.03);
    for (auto f : relaxed.faces()) {
      Vec3 centre(0, 0, 0);
      for (auto v : relaxed.fv_range(f)) centre += relaxed.point(v) / static_cast<double>(relaxed.valence(f));
      CHECK((polygon_normal(relaxed, f) | s.outward(centre)) > 0);
    }
    // Whatever the thread count, the same points.
    PolyMesh again = centroids;
    relax_bonds(again, p.e_min, p.e_max, reference, 2);
    for (auto v : relaxed.vertices()) CHECK(again.point(v) == relaxed.point(v));
  }
}

TEST_CASE("relaxing bonds already inside the interval changes nothing", "[dual]") {
  TriMesh mesh = test::make_icosphere(3, kRadius);
  const ReferenceSurface reference(mesh);
  PolyMesh dual = trivalent_dual(mesh, &reference);
  const PolyMesh before = dual;
  const BondRelaxation r = relax_bonds(dual, 1e-6, 1e6, reference);
  CHECK(r.iterations == 0);
  CHECK(r.inside_after == r.bonds);
  for (auto v : dual.vertices()) CHECK(dual.point(v) == before.point(v));
}

TEST_CASE("atoms in one place are pushed apart", "[dual]") {
  // A whole ring in one point (the projection can put the three centroids around a valence-3
  // vertex on one corner of a thin part): a ring with no area, and bonds with no direction.
  const TriMesh mesh = test::make_icosphere(3, kRadius);
  const ReferenceSurface reference(mesh);
  PolyMesh dual = trivalent_dual(mesh, &reference);
  double rest = 0;
  for (auto e : dual.edges()) rest += dual.calc_edge_length(e) / static_cast<double>(dual.n_edges());
  const auto ring = dual.face_handle(0);
  std::vector<PolyMesh::VertexHandle> atoms(dual.fv_range(ring).begin(), dual.fv_range(ring).end());
  for (auto v : atoms) dual.point(v) = dual.point(atoms[0]);
  const BondRelaxation r = relax_bonds(dual, 0.9 * kRoot3 * rest, 1.1 * kRoot3 * rest, reference);
  CHECK(r.iterations > 0);
  for (auto e : dual.edges()) CHECK(dual.calc_edge_length(e) > 0.5 * rest);
  CHECK(r.inside_after == r.bonds);
}

TEST_CASE("an interval open upward or an atom whose bonds all have no length stay in bounds", "[dual]") {
  const TriMesh mesh = test::make_icosphere(3, kRadius);
  const ReferenceSurface reference(mesh);
  const PolyMesh start = trivalent_dual(mesh, &reference);
  double mean = 0, longest = 0;
  for (auto e : start.edges()) {
    mean += start.calc_edge_length(e) / static_cast<double>(start.n_edges());
    longest = std::max(longest, start.calc_edge_length(e));
  }
  // Bonds of at least 1.2 x the mean and at most 1e300: the rest length stays near the bonds'.
  PolyMesh wide = start;
  const BondRelaxation r = relax_bonds(wide, 1.2 * kRoot3 * mean, 1e300, reference);
  CHECK(r.iterations > 0);
  for (auto e : wide.edges()) CHECK(wide.calc_edge_length(e) < 2 * longest);
  for (auto v : wide.vertices()) CHECK(std::abs(wide.point(v).norm() - kRadius) < 0.05);
  // An interval far below the bonds (a run that did not reach it): the atoms stay on the surface.
  PolyMesh tight = start;
  relax_bonds(tight, 0.2 * kRoot3 * mean, 0.3 * kRoot3 * mean, reference);
  for (auto v : tight.vertices()) CHECK(std::abs(tight.point(v).norm() - kRadius) < 0.05);
  for (auto e : tight.edges()) CHECK(tight.calc_edge_length(e) > 0);
  // An atom and its three neighbours in one place: the atom has no direction to go at first.
  PolyMesh lumped = start;
  const auto a = lumped.vertex_handle(0);
  for (auto w : lumped.vv_range(a)) lumped.point(w) = lumped.point(a);
  relax_bonds(lumped, 0.9 * kRoot3 * mean, 1.1 * kRoot3 * mean, reference);
  for (auto v : lumped.vertices()) {
    const Vec3& p = lumped.point(v);
    CHECK((std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2])));
    CHECK(std::abs(p.norm() - kRadius) < 0.05);
  }
  for (auto e : lumped.edges()) CHECK(lumped.calc_edge_length(e) > 0.3 * mean);
}
