/// \file trivalent_dual_test.cpp
/// Properties of the trivalent dual on closed, open, high-genus and hexagonal meshes.

#include <catch2/catch.hpp>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "dual/trivalent_dual.h"
#include "support/mesh_generators.h"

using namespace remesh;
using remesh::test::make_double_torus;
using remesh::test::make_hex_lattice_patch;
using remesh::test::make_icosphere;
using remesh::test::make_open_grid;
using remesh::test::make_torus;

namespace {

Vec3 centroid_of(const TriMesh& m, OpenMesh::FaceHandle f) {
  Vec3 c(0, 0, 0);
  for (auto v : m.fv_range(f)) c += m.point(v);
  return c / 3.0;
}

/// Area-weighted normal of a polygon (Newell), unnormalised.
Vec3 polygon_normal(const PolyMesh& d, OpenMesh::FaceHandle f) {
  Vec3 n(0, 0, 0);
  for (auto h : d.fh_range(f)) {
    const Vec3& a = d.point(d.from_vertex_handle(h));
    const Vec3& b = d.point(d.to_vertex_handle(h));
    n += OpenMesh::cross(a, b);
  }
  return n;
}

/// Primal vertex normal as the sum of its incident triangles' area vectors.
Vec3 vertex_area_normal(const TriMesh& m, OpenMesh::VertexHandle v) {
  Vec3 n(0, 0, 0);
  for (auto f : m.vf_range(v)) {
    auto h = m.halfedge_handle(f);
    const Vec3& a = m.point(m.from_vertex_handle(h));
    const Vec3& b = m.point(m.to_vertex_handle(h));
    const Vec3& c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
    n += OpenMesh::cross(b - a, c - a);
  }
  return n;
}

std::size_t interior_vertex_count(const TriMesh& m) {
  std::size_t n = 0;
  for (auto v : m.vertices()) n += m.is_boundary(v) ? 0 : 1;
  return n;
}

/// Primal edges with at least one interior end vertex: each borders a dual face, so is a dual edge.
std::size_t edges_touching_interior(const TriMesh& m) {
  std::size_t n = 0;
  for (auto e : m.edges()) {
    auto h = m.halfedge_handle(e, 0);
    n += (!m.is_boundary(m.from_vertex_handle(h)) || !m.is_boundary(m.to_vertex_handle(h))) ? 1 : 0;
  }
  return n;
}

/// Every dual edge joins the dual vertices (= centroids) of two primal triangles sharing an edge.
void check_dual_edges_join_adjacent_triangles(const TriMesh& primal, const PolyMesh& dual) {
  std::set<std::pair<int, int>> adjacent;
  for (auto e : primal.edges()) {
    if (primal.is_boundary(e)) continue;
    int a = primal.face_handle(primal.halfedge_handle(e, 0)).idx();
    int b = primal.face_handle(primal.halfedge_handle(e, 1)).idx();
    adjacent.emplace(std::min(a, b), std::max(a, b));
  }
  for (auto e : dual.edges()) {
    auto h = dual.halfedge_handle(e, 0);
    int a = dual.from_vertex_handle(h).idx(), b = dual.to_vertex_handle(h).idx();
    INFO("dual edge " << a << "-" << b);
    CHECK(adjacent.count({std::min(a, b), std::max(a, b)}) == 1);
  }
  for (auto f : primal.faces()) {
    const Vec3 diff = dual.point(OpenMesh::VertexHandle(f.idx())) - centroid_of(primal, f);
    REQUIRE(diff.norm() < 1e-12);
  }
}

/// Each dual face is the face of one interior primal vertex; its normal agrees with that vertex's.
/// The face's vertex is recognised as the primal vertex shared by all its triangles.
void check_face_orientation(const TriMesh& primal, const PolyMesh& dual) {
  for (auto df : dual.faces()) {
    std::map<int, int> corner_count;
    std::size_t size = 0;
    for (auto dv : dual.fv_range(df)) {
      ++size;
      for (auto pv : primal.fv_range(OpenMesh::FaceHandle(dv.idx()))) ++corner_count[pv.idx()];
    }
    int centre = -1;
    for (auto [v, count] : corner_count)
      if (static_cast<std::size_t>(count) == size) centre = v;
    REQUIRE(centre >= 0);
    const OpenMesh::VertexHandle pv(centre);
    CHECK(!primal.is_boundary(pv));
    CHECK(primal.valence(pv) == size);
    const double dot = OpenMesh::dot(polygon_normal(dual, df).normalized(),
                                     vertex_area_normal(primal, pv).normalized());
    INFO("dual face " << df.idx() << " of primal vertex " << centre);
    CHECK(dot > 0);
  }
}

void check_closed(const TriMesh& primal) {
  const PolyMesh dual = trivalent_dual(primal);
  REQUIRE(dual.n_vertices() == primal.n_faces());
  REQUIRE(dual.n_faces() == primal.n_vertices());
  REQUIRE(dual.n_edges() == primal.n_edges());
  for (auto v : dual.vertices()) {
    CHECK(dual.valence(v) == 3);
    CHECK(!dual.is_boundary(v));
  }
  check_dual_edges_join_adjacent_triangles(primal, dual);
  check_face_orientation(primal, dual);
}

}  // namespace

TEST_CASE("dual of closed meshes: V*=F, F*=V, E*=E, trivalent, oriented like the primal", "[dual]") {
  SECTION("icosphere") { check_closed(make_icosphere(2)); }
  SECTION("torus") { check_closed(make_torus(24, 12, 2.0, 0.6)); }
  SECTION("genus 2") { check_closed(make_double_torus()); }
}

TEST_CASE("dual of a flipped sphere is flipped too", "[dual]") {
  TriMesh sphere = make_icosphere(1);
  // Rebuild with every triangle reversed: the dual faces must then point inward as well.
  TriMesh flipped;
  for (auto v : sphere.vertices()) flipped.add_vertex(sphere.point(v));
  for (auto f : sphere.faces()) {
    std::vector<TriMesh::VertexHandle> c(sphere.fv_begin(f), sphere.fv_end(f));
    flipped.add_face(c[2], c[1], c[0]);
  }
  const PolyMesh dual = trivalent_dual(flipped);
  REQUIRE(dual.n_faces() == flipped.n_vertices());
  for (auto f : dual.faces()) {
    // Outward on a sphere centred at the origin is the direction of the face's centre.
    Vec3 centre(0, 0, 0);
    for (auto v : dual.fv_range(f)) centre += dual.point(v);
    CHECK(OpenMesh::dot(polygon_normal(dual, f), centre) < 0);
  }
  check_face_orientation(flipped, dual);
}

TEST_CASE("a lattice whose interior vertices have valence 6 gives hexagons only", "[dual]") {
  const TriMesh patch = make_hex_lattice_patch(9, 11, 1.0);
  const PolyMesh dual = trivalent_dual(patch);
  const std::size_t interior = interior_vertex_count(patch);
  REQUIRE(interior > 20);
  REQUIRE(dual.n_faces() == interior);
  for (auto f : dual.faces()) CHECK(dual.valence(f) == 6);
  // Equilateral triangles of side a: the dual edge is a / sqrt(3).
  for (auto e : dual.edges()) CHECK(dual.calc_edge_length(e) == Approx(1.0 / std::sqrt(3.0)).epsilon(1e-9));
  // Interior dual vertices (triangles with three interior corners) are trivalent.
  for (auto v : dual.vertices()) {
    auto f = OpenMesh::FaceHandle(v.idx());
    bool all_interior = true;
    for (auto pv : patch.fv_range(f)) all_interior = all_interior && !patch.is_boundary(pv);
    if (all_interior) CHECK(dual.valence(v) == 3);
  }
  check_face_orientation(patch, dual);
}

TEST_CASE("open meshes: no face for boundary vertices, dual vertex per triangle kept", "[dual]") {
  const TriMesh grid = make_open_grid(7, 5, 0.5);
  const PolyMesh dual = trivalent_dual(grid);
  REQUIRE(dual.n_vertices() == grid.n_faces());
  REQUIRE(dual.n_faces() == interior_vertex_count(grid));
  REQUIRE(dual.n_edges() == edges_touching_interior(grid));
  // Corner diagonals join two boundary vertices: interior edges, yet no dual face borders them.
  std::size_t interior_edges = 0;
  for (auto e : grid.edges()) interior_edges += grid.is_boundary(e) ? 0 : 1;
  CHECK(dual.n_edges() <= interior_edges);
  check_dual_edges_join_adjacent_triangles(grid, dual);
  check_face_orientation(grid, dual);
}

TEST_CASE("a sphere with a hole: dual edges = interior primal edges", "[dual]") {
  TriMesh sphere = make_icosphere(2);
  sphere.delete_vertex(OpenMesh::VertexHandle(0));  // removes its star, leaving one hole
  sphere.garbage_collection();
  std::size_t interior_edges = 0;
  for (auto e : sphere.edges()) interior_edges += sphere.is_boundary(e) ? 0 : 1;
  const PolyMesh dual = trivalent_dual(sphere);
  REQUIRE(dual.n_vertices() == sphere.n_faces());
  REQUIRE(dual.n_faces() == interior_vertex_count(sphere));
  REQUIRE(dual.n_faces() + 5 == sphere.n_vertices());  // vertex 0 had valence 5
  REQUIRE(dual.n_edges() == interior_edges);
  check_dual_edges_join_adjacent_triangles(sphere, dual);
  check_face_orientation(sphere, dual);
}

TEST_CASE("dual of a mesh with deleted elements matches the dual of its compacted copy", "[dual]") {
  TriMesh sphere = make_icosphere(2);
  // Delete one vertex's faces by collapsing one edge (marks elements deleted, no garbage collection).
  auto h = sphere.halfedge_handle(sphere.edge_handle(0), 0);
  REQUIRE(sphere.is_collapse_ok(h));
  sphere.collapse(h);
  TriMesh compact = sphere;
  compact.garbage_collection();
  const PolyMesh a = trivalent_dual(sphere);
  const PolyMesh b = trivalent_dual(compact);
  REQUIRE(a.n_vertices() == compact.n_faces());
  REQUIRE(a.n_faces() == compact.n_vertices());
  REQUIRE(a.n_faces() == b.n_faces());
  for (auto v : a.vertices()) CHECK((a.point(v) - b.point(v)).norm() == 0);
}

#ifdef REMESH_DUAL_TEST_PROJECTION
#include "remesh/reference_surface.h"

TEST_CASE("projected dual vertices lie on the reference surface", "[dual]") {
  // Centroids of a coarse sphere's triangles lie inside the unit sphere; projected onto a fine
  // unit sphere they move out to (nearly) radius 1. Connectivity does not change.
  const TriMesh coarse = make_icosphere(1);
  const ReferenceSurface fine(make_icosphere(4));
  const PolyMesh plain = trivalent_dual(coarse);
  const PolyMesh projected = trivalent_dual(coarse, &fine);
  REQUIRE(projected.n_vertices() == plain.n_vertices());
  REQUIRE(projected.n_faces() == plain.n_faces());
  REQUIRE(projected.n_edges() == plain.n_edges());
  double worst_plain = 0, worst_projected = 0;
  for (auto v : projected.vertices()) {
    worst_plain = std::max(worst_plain, std::abs(plain.point(v).norm() - 1.0));
    worst_projected = std::max(worst_projected, std::abs(projected.point(v).norm() - 1.0));
  }
  CHECK(worst_plain > 0.05);
  CHECK(worst_projected < 0.01);  // a level-4 icosphere deviates from the sphere by < 0.005
  check_face_orientation(coarse, projected);

  // Projected onto the primal itself, a centroid stays where it is.
  const ReferenceSurface self(coarse);
  const PolyMesh onto_self = trivalent_dual(coarse, &self);
  for (auto v : onto_self.vertices()) CHECK((onto_self.point(v) - plain.point(v)).norm() < 1e-9);
}
#endif
