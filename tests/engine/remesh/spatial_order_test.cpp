// The mesh numbered anew in space order (spatial_order.h): the same mesh, neighbours near in memory.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "remesh/spatial_order.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

using Ring = std::vector<std::array<double, 3>>;

std::array<double, 3> key(const Vec3& p) { return {p[0], p[1], p[2]}; }

/// Each vertex's ring, as positions in circulation order from its first outgoing halfedge, with
/// its own position first and a marker for a boundary vertex; sorted, so that two numberings of
/// the same mesh give the same list.
std::vector<Ring> rings(const TriMesh& mesh) {
  std::vector<Ring> out;
  for (auto v : mesh.vertices()) {
    Ring ring{key(mesh.point(v)), {mesh.is_boundary(v) ? 1.0 : 0.0, 0, 0}};
    for (auto w : mesh.vv_range(v)) ring.push_back(key(mesh.point(w)));
    out.push_back(ring);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Each face as its corners' positions from its first halfedge (orientation and start kept), sorted.
std::vector<Ring> faces(const TriMesh& mesh) {
  std::vector<Ring> out;
  for (auto f : mesh.faces()) {
    Ring corners;
    for (auto v : mesh.fv_range(f)) corners.push_back(key(mesh.point(v)));
    out.push_back(corners);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Mean difference of the indices of an edge's two ends: how far apart neighbours lie in memory.
double mean_index_gap(const TriMesh& mesh) {
  double sum = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    sum += std::abs(mesh.from_vertex_handle(h).idx() - mesh.to_vertex_handle(h).idx());
  }
  return sum / static_cast<double>(mesh.n_edges());
}

/// Splits at random edges, as the stellar operations do: the new vertices go to the end, in no
/// order of space.
void split_randomly(TriMesh& mesh, unsigned seed, int splits) {
  std::mt19937 rng(seed);
  for (int i = 0; i < splits; ++i) {
    std::uniform_int_distribution<int> pick(0, static_cast<int>(mesh.n_edges()) - 1);
    const auto e = mesh.edge_handle(pick(rng));
    const auto h = mesh.halfedge_handle(e, 0);
    mesh.split(e, 0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h))));
  }
}

}  // namespace

TEST_CASE("spatial order numbers the same mesh anew, neighbours nearer in memory", "[spatial_order]") {
  struct Case {
    std::string name;
    TriMesh mesh;
  };
  std::vector<Case> cases;
  cases.push_back({"icosphere", test::make_icosphere(4, 3.0)});
  cases.push_back({"torus", test::make_torus(48, 24, 4.0, 1.5)});
  cases.push_back({"open grid", test::make_open_grid(40, 30, 0.5)});
  cases.push_back({"plate with holes", test::make_plate_with_holes(3)});
  for (Case& c : cases) {
    SECTION(c.name) {
      TriMesh& mesh = c.mesh;
      split_randomly(mesh, 7, static_cast<int>(mesh.n_vertices()));
      const std::size_t nv = mesh.n_vertices(), ne = mesh.n_edges(), nf = mesh.n_faces();
      const auto rings_before = rings(mesh);
      const auto faces_before = faces(mesh);
      std::vector<Vec3> points;
      for (auto v : mesh.vertices()) points.push_back(mesh.point(v));
      const long euler = test::euler_characteristic(mesh);
      const std::size_t loops = test::count_boundary_loops(mesh);
      const double gap_before = mean_index_gap(mesh);
      TriMesh copy = mesh;

      const std::vector<unsigned> order = spatial_order(mesh);

      REQUIRE(test::check_mesh_valid(mesh).empty());
      CHECK(mesh.n_vertices() == nv);
      CHECK(mesh.n_edges() == ne);
      CHECK(mesh.n_faces() == nf);
      REQUIRE(order.size() == nv);
      for (std::size_t v = 0; v < nv; ++v) CHECK(mesh.point(mesh.vertex_handle(order[v])) == points[v]);
      // Every circulation starts and runs as before; every face keeps its corners in order.
      CHECK(rings(mesh) == rings_before);
      CHECK(faces(mesh) == faces_before);
      CHECK(test::euler_characteristic(mesh) == euler);
      CHECK(test::count_boundary_loops(mesh) == loops);
      // The splits scattered the new vertices; in space order an edge's ends lie close in memory.
      CHECK(mean_index_gap(mesh) < 0.25 * gap_before);
      // Its parallel loops give the same numbering on two threads.
      CHECK(spatial_order(copy, 2) == order);
      for (auto e : mesh.edges()) {
        const OpenMesh::HalfedgeHandle h = mesh.halfedge_handle(e, 0), g = copy.halfedge_handle(copy.edge_handle(e.idx()), 0);
        CHECK(mesh.to_vertex_handle(h) == copy.to_vertex_handle(g));
        CHECK(mesh.next_halfedge_handle(h) == copy.next_halfedge_handle(g));
        CHECK(mesh.face_handle(h) == copy.face_handle(g));
      }
    }
  }
}

TEST_CASE("spatial order keeps an isolated vertex", "[spatial_order]") {
  TriMesh mesh = test::make_icosphere(1);
  mesh.add_vertex(Vec3(5, 5, 5));
  const std::size_t nv = mesh.n_vertices(), nf = mesh.n_faces();
  const std::vector<unsigned> order = spatial_order(mesh);
  REQUIRE(order.size() == nv);
  CHECK(mesh.n_faces() == nf);
  const auto isolated = mesh.vertex_handle(order[nv - 1]);
  CHECK(mesh.is_isolated(isolated));
  CHECK(mesh.point(isolated) == Vec3(5, 5, 5));
}
