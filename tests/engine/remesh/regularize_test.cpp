// The look-ahead flips (regularize.h), alone.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <random>

#include "remesh/regularize.h"
#include "remesh/valence_flips.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

/// Sum over vertices of |valence - target| (6 inside, 4 on the boundary), by circulation.
long total_deviation(const TriMesh& m) {
  long d = 0;
  for (auto v : m.vertices()) d += std::abs(static_cast<long>(m.valence(v)) - (m.is_boundary(v) ? 4 : 6));
  return d;
}

/// A mesh with defects: legal flips at random edges, then Algorithm 4's flips until none is left.
TriMesh scrambled(TriMesh mesh, unsigned seed, int flips) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<unsigned> pick(0, static_cast<unsigned>(mesh.n_edges() - 1));
  for (int i = 0; i < flips; ++i) {
    const auto e = mesh.edge_handle(pick(rng));
    if (flip_is_safe(mesh, e, 0.3)) mesh.flip(e);
  }
  while (valence_flips(mesh, 0.5, 10) > 0) {
  }
  return mesh;
}

}  // namespace

TEST_CASE("look-ahead flips lower the valence deviation by at least one per flip or pair, and stay valid",
          "[steps]") {
  const TriMesh inputs[] = {scrambled(test::make_torus(40, 20, 3.0, 1.0), 1, 600),
                            scrambled(test::make_icosphere(4), 2, 800),
                            scrambled(test::make_double_torus(1.0, 3), 3, 400),
                            scrambled(test::make_open_grid(24, 24, 1.0), 4, 500)};
  std::size_t pairs_seen = 0;
  for (const TriMesh& input : inputs) {
    TriMesh mesh = input;
    const long before = total_deviation(mesh);
    const long euler = test::euler_characteristic(mesh);
    const std::size_t loops = test::count_boundary_loops(mesh);
    // Algorithm 4 has nothing left to flip here.
    REQUIRE(valence_flip_sweep(mesh, 0.5) == 0);
    const RegularizeCounts counts = regularize(mesh, 0.5, 20);
    pairs_seen += counts.pairs;
    const long after = total_deviation(mesh);
    CHECK(before - after >= static_cast<long>(counts.single + counts.pairs));
    CHECK(test::check_mesh_valid(mesh) == "");
    CHECK(test::euler_characteristic(mesh) == euler);
    CHECK(test::count_boundary_loops(mesh) == loops);
    CHECK(mesh.n_vertices() == input.n_vertices());
    // Sweeps stop when one flips nothing: a further pass finds nothing either.
    const RegularizeCounts more = regularize(mesh, 0.5, 1);
    CHECK(more.single + more.pairs == 0);
  }
  // The scrambled meshes hold neutral moves that open an improving one.
  CHECK(pairs_seen > 0);
}
