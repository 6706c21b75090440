// The look-ahead flips (regularize.h), alone.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <random>
#include <utility>
#include <vector>

#include "remesh/geometry.h"
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

/// Legal flips at random edges: many valence defects.
TriMesh randomly_flipped(TriMesh mesh, unsigned seed, int flips) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<unsigned> pick(0, static_cast<unsigned>(mesh.n_edges() - 1));
  for (int i = 0; i < flips; ++i) {
    const auto e = mesh.edge_handle(pick(rng));
    if (flip_is_safe(mesh, e, 0.3)) mesh.flip(e);
  }
  return mesh;
}

/// A mesh with defects: randomly_flipped, then Algorithm 4's flips until none is left.
TriMesh scrambled(TriMesh mesh, unsigned seed, int flips) {
  mesh = randomly_flipped(std::move(mesh), seed, flips);
  while (valence_flips(mesh, 0.5, 10) > 0) {
  }
  return mesh;
}

}  // namespace

TEST_CASE("look-ahead flips lower the valence deviation by at least one per flip or chain, and stay valid",
          "[steps]") {
  const TriMesh inputs[] = {scrambled(test::make_torus(40, 20, 3.0, 1.0), 1, 600),
                            scrambled(test::make_icosphere(4), 2, 800),
                            scrambled(test::make_double_torus(1.0, 3), 3, 400),
                            scrambled(test::make_open_grid(24, 24, 1.0), 4, 500)};
  for (int depth : {1, 2}) {
    INFO("depth " << depth);
    std::size_t chains_seen = 0, long_chains = 0;
    for (const TriMesh& input : inputs) {
      TriMesh mesh = input;
      const long before = total_deviation(mesh);
      const long euler = test::euler_characteristic(mesh);
      const std::size_t loops = test::count_boundary_loops(mesh);
      // Algorithm 4 has nothing left to flip here.
      REQUIRE(valence_flip_sweep(mesh, 0.5) == 0);
      const RegularizeCounts counts = regularize(mesh, 0.5, 20, 1, nullptr, depth);
      chains_seen += counts.chains;
      // A chain is `depth` + 1 flips at most: neutral ones, then the one that lowers the deviation.
      CHECK(counts.chain_flips >= 2 * counts.chains);
      CHECK(counts.chain_flips <= static_cast<std::size_t>(depth + 1) * counts.chains);
      long_chains += counts.chain_flips - 2 * counts.chains;
      const long after = total_deviation(mesh);
      CHECK(before - after >= static_cast<long>(counts.single + counts.chains));
      CHECK(test::check_mesh_valid(mesh) == "");
      CHECK(test::euler_characteristic(mesh) == euler);
      CHECK(test::count_boundary_loops(mesh) == loops);
      CHECK(mesh.n_vertices() == input.n_vertices());
      // Sweeps stop when one flips nothing: a further pass finds nothing either.
      const RegularizeCounts more = regularize(mesh, 0.5, 1, 1, nullptr, depth);
      CHECK(more.single + more.chains == 0);
    }
    // The scrambled meshes hold neutral moves that open an improving one, and some need two.
    CHECK(chains_seen > 0);
    CHECK((depth == 1 ? long_chains == 0 : long_chains > 0));
  }
}

namespace {

/// The triangles of a mesh as vertex index triples, each rotated to start at its smallest index,
/// sorted: equal lists mean equal connectivity.
std::vector<std::array<int, 3>> triangles_of(const TriMesh& m) {
  std::vector<std::array<int, 3>> out;
  for (auto f : m.faces()) {
    std::array<int, 3> t{};
    int k = 0;
    for (auto v : m.fv_range(f)) t[k++] = v.idx();
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

namespace {

/// Flips counted by a sweep procedure: Algorithm 4's alone, or single look-ahead flips and chains.
struct FlipCount {
  std::size_t single = 0, chains = 0;
};

/// Runs `walked` and `full` (each flips its own copy of the input with the given sweep count) on
/// every input and sweep count: they must flip as many edges and leave the same triangles. Returns
/// what `walked` flipped, summed.
template <class Walked, class Full>
FlipCount check_same_flips(const std::vector<TriMesh>& inputs, std::initializer_list<int> sweep_counts,
                           Walked walked, Full full) {
  FlipCount total;
  for (const TriMesh& input : inputs)
    for (int sweeps : sweep_counts) {
      TriMesh a = input, b = input;
      const FlipCount na = walked(a, sweeps), nb = full(b, sweeps);
      CHECK(na.single == nb.single);
      CHECK(na.chains == nb.chains);
      CHECK(triangles_of(a) == triangles_of(b));
      total.single += na.single, total.chains += na.chains;
    }
  return total;
}

}  // namespace

TEST_CASE("sweeps that visit only the edges around touched vertices flip exactly what full sweeps flip",
          "[steps]") {
  // valence_flips walks the later sweeps over the edges SweepMarks offers; valence_flip_sweep scans
  // every edge. Random legal flips leave many defects, so the sweeps flip a lot (and the later ones
  // see edges offered during the sweep itself).
  std::vector<TriMesh> inputs;
  for (unsigned seed = 1; seed <= 6; ++seed)
    inputs.push_back(
        randomly_flipped(seed % 2 ? test::make_torus(36, 18, 3.0, 1.0) : test::make_icosphere(4), seed, 700));
  std::size_t later_flips = 0;
  check_same_flips(
      inputs, {1, 2, 3, 4}, [](TriMesh& m, int sweeps) { return FlipCount{valence_flips(m, 0.5, sweeps)}; },
      [&](TriMesh& m, int sweeps) {
        FlipCount n;
        for (int s = 0; s < sweeps; ++s) {
          const std::size_t flipped = valence_flip_sweep(m, 0.5);
          n.single += flipped;
          if (s > 0) later_flips += flipped;
          if (flipped == 0) break;
        }
        return n;
      });
  CHECK(later_flips > 0);
}

namespace {

/// The look-ahead flips as regularize.h states them, with full sweeps over every edge: the
/// reference for the sweeps that visit only the edges around touched vertices. (The cone rule is
/// the engine's cones_kept, tested on its own below.)
/// Flips e (neutral), then looks for an improving flip at the quad's corners, else (depth > 1) for
/// a neutral one there to go on from; `chain` holds the edges flipped so far. Undoes on failure.
bool reference_chain(TriMesh& mesh, VertexInfo& info, OpenMesh::EdgeHandle e, const Quad& q, double f, int depth,
                     std::vector<OpenMesh::EdgeHandle>& chain, std::size_t& flips) {
  mesh.flip(e);
  info.flipped(q);
  chain.push_back(e);
  std::vector<OpenMesh::EdgeHandle> around;
  for (auto corner : {q.v0, q.v1, q.v2, q.v3})
    for (auto h : mesh.voh_range(corner)) {
      const auto g = mesh.edge_handle(h);
      if (!mesh.is_boundary(g) && std::find(chain.begin(), chain.end(), g) == chain.end()) around.push_back(g);
    }
  bool done = false;
  for (auto g : around) {
    const Quad r = quad_of(mesh, g);
    if (info.gain(r) > 0 && flip_is_safe(mesh, g, f)) {
      mesh.flip(g);
      info.flipped(r);
      flips = chain.size() + 1;
      done = true;
      break;
    }
  }
  for (std::size_t i = 0; depth > 1 && !done && i < around.size(); ++i) {
    const Quad r = quad_of(mesh, around[i]);
    if (info.gain(r) == 0 && flip_is_safe(mesh, around[i], f) && cones_kept(mesh, info, r))
      done = reference_chain(mesh, info, around[i], r, f, depth - 1, chain, flips);
  }
  chain.pop_back();
  if (!done) {
    const Quad back = quad_of(mesh, e);
    mesh.flip(e);
    info.flipped(back);
  }
  return done;
}

RegularizeCounts reference_regularize(TriMesh& mesh, double f, int max_sweeps, int depth) {
  RegularizeCounts counts;
  VertexInfo info(mesh);
  std::size_t flips = 0;
  for (int s = 0; s < max_sweeps; ++s) {
    std::size_t done = 0;
    for (auto e : mesh.edges()) {
      if (mesh.is_boundary(e)) continue;
      const Quad q = quad_of(mesh, e);
      const int gain = info.gain(q);
      if (gain < 0 || !flip_is_safe(mesh, e, f)) continue;
      if (gain > 0) {
        mesh.flip(e);
        info.flipped(q);
        ++counts.single, ++done;
      } else if (std::vector<OpenMesh::EdgeHandle> chain; (depth == 1 || cones_kept(mesh, info, q)) &&
                 reference_chain(mesh, info, e, q, f, depth, chain, flips)) {
        ++counts.chains, ++done;
        counts.chain_flips += flips;
      }
    }
    if (done == 0) break;
  }
  return counts;
}

}  // namespace

TEST_CASE("look-ahead flips over the edges around touched vertices make exactly the flips of full sweeps",
          "[steps]") {
  std::vector<TriMesh> inputs;
  for (unsigned seed = 1; seed <= 6; ++seed)
    inputs.push_back(scrambled(seed % 3 == 0   ? test::make_double_torus(1.0, 3)
                               : seed % 3 == 1 ? test::make_torus(36, 18, 3.0, 1.0)
                                               : test::make_open_grid(24, 24, 1.0),
                               seed, 700));
  auto counted = [](RegularizeCounts c) { return FlipCount{c.single, c.chains}; };
  for (int depth : {1, 2, 3}) {
    const FlipCount walked = check_same_flips(
        inputs, {1, 2, 20},
        [&](TriMesh& m, int sweeps) { return counted(regularize(m, 0.5, sweeps, 1, nullptr, depth)); },
        [&](TriMesh& m, int sweeps) { return counted(reference_regularize(m, 0.5, sweeps, depth)); });
    CHECK(walked.chains > 0);
  }
}

namespace {

/// A fan of `n` triangles around a centre vertex at height `lift`, its rim on the unit circle with
/// the rim vertex k at height `rim(k)`, and one more triangle across the rim edge (rim 0, rim 1) to
/// an outer vertex. Returns the mesh and the quad of the edge named by `edge`: the rim edge (rim 0,
/// rim 1), whose flip gives the centre one more edge, or the spoke (centre, rim 1), whose flip
/// takes one from it.
enum class FanEdge { Rim, Spoke };
std::pair<TriMesh, Quad> fan(int n, double lift, double (*rim)(int), FanEdge edge) {
  TriMesh m;
  const auto c = m.add_vertex(Vec3(0, 0, lift));
  std::vector<OpenMesh::VertexHandle> ring;
  for (int k = 0; k < n; ++k) {
    const double a = 2 * M_PI * k / n;
    ring.push_back(m.add_vertex(Vec3(std::cos(a), std::sin(a), rim(k))));
  }
  for (int k = 0; k < n; ++k) m.add_face(c, ring[k], ring[(k + 1) % n]);
  const double a = M_PI / n;  // beyond the middle of the rim edge (rim 0, rim 1)
  const auto outer = m.add_vertex(Vec3(2 * std::cos(a), 2 * std::sin(a), 0));
  m.add_face(ring[1], ring[0], outer);
  OpenMesh::EdgeHandle e;
  const auto [from, to] = edge == FanEdge::Rim ? std::pair{ring[0], ring[1]} : std::pair{c, ring[1]};
  for (auto h : m.voh_range(from))
    if (m.to_vertex_handle(h) == to) e = m.edge_handle(h);
  const Quad q = quad_of(m, e);
  return {std::move(m), q};
}

double flat(int) { return 0; }
double saddle(int k) { return k % 2 ? 0.6 : -0.6; }

}  // namespace

TEST_CASE("the cone rule keeps a 5 on a cone point and a 7 on a saddle irregular, not on flat ground", "[steps]") {
  // A valence-5 centre, whose rim-edge flip makes it regular: refused when the centre is a cone's
  // apex (deficit over kConeDeficit), allowed when the fan is flat.
  for (double lift : {0.0, 0.3, 1.5}) {
    auto [m, q] = fan(5, lift, flat, FanEdge::Rim);
    const VertexInfo info(m);
    REQUIRE(info.valence[0] == 5);
    REQUIRE((q.v2.idx() == 0 || q.v3.idx() == 0));  // the centre gains the edge
    const double deficit = geom::angle_deficit(m, m.vertex_handle(0));
    INFO("lift " << lift << ", deficit " << deficit);
    CHECK(cones_kept(m, info, q) == !(deficit > kConeDeficit));
    if (lift == 0.0) CHECK(cones_kept(m, info, q));
    if (lift == 1.5) CHECK_FALSE(cones_kept(m, info, q));
  }
  // A valence-7 centre, whose spoke flip makes it regular: refused on a saddle, allowed when flat.
  for (bool bent : {false, true}) {
    auto [m, q] = fan(7, 0, bent ? saddle : flat, FanEdge::Spoke);
    const VertexInfo info(m);
    REQUIRE(info.valence[0] == 7);
    REQUIRE((q.v0.idx() == 0 || q.v1.idx() == 0));  // the centre loses the edge
    INFO("deficit " << geom::angle_deficit(m, m.vertex_handle(0)));
    CHECK(geom::angle_deficit(m, m.vertex_handle(0)) < (bent ? -kConeDeficit : 1e-9));
    CHECK(cones_kept(m, info, q) == !bent);
  }
}
