// summarize(): counts, components, boundaries, genus, bounding box, edge lengths, area.
#include <catch2/catch.hpp>

#include <cmath>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "support/mesh_generators.h"

using namespace remesh;

TEST_CASE("Summary of closed meshes of genus 0, 1 and 2") {
  struct Case {
    TriMesh mesh;
    int genus;
  };
  std::vector<Case> cases;
  cases.push_back({test::make_icosphere(2), 0});
  cases.push_back({test::make_torus(16, 10, 3, 1), 1});
  cases.push_back({test::make_double_torus(), 2});
  for (const Case& c : cases) {
    MeshSummary s = summarize(c.mesh);
    CHECK(s.vertices == c.mesh.n_vertices());
    CHECK(s.faces == c.mesh.n_faces());
    CHECK(s.edges == c.mesh.n_edges());
    CHECK(s.euler == 2 - 2 * c.genus);
    CHECK(s.euler == test::euler_characteristic(c.mesh));
    CHECK(s.components == 1);
    CHECK(s.boundary_loops == 0);
    CHECK(s.boundary_edges == 0);
    REQUIRE(s.per_component.size() == 1);
    CHECK(s.per_component[0].closed);
    CHECK(s.per_component[0].genus == c.genus);
    CHECK(s.min_edge > 0);
    CHECK(s.min_edge <= s.mean_edge);
    CHECK(s.mean_edge <= s.max_edge);
  }
}

TEST_CASE("Summary of an icosphere: bounding box, edges and area") {
  MeshSummary s = summarize(test::make_icosphere(3, 2.0));
  CHECK(s.bbox_min[0] == Approx(-2.0));
  CHECK(s.bbox_max[1] == Approx(2.0));
  CHECK(s.bbox_diagonal == Approx((s.bbox_max - s.bbox_min).norm()));
  CHECK(s.area < 4 * M_PI * 4);
  CHECK(s.area > 0.97 * 4 * M_PI * 4);
  CHECK(s.mean_edge * s.mean_edge * std::sqrt(3.0) / 4 * static_cast<double>(s.faces) == Approx(s.area).epsilon(0.05));
}

TEST_CASE("Summary of an open grid and of several components") {
  MeshSummary g = summarize(test::make_open_grid(6, 4, 0.5));
  CHECK(g.boundary_loops == 1);
  CHECK(g.boundary_edges == 2 * (6 + 4));
  CHECK(g.area == Approx(6 * 4 * 0.25));
  CHECK(g.min_edge == Approx(0.5));
  CHECK(g.max_edge == Approx(0.5 * std::sqrt(2.0)));
  CHECK(g.per_component.at(0).genus == 0);
  CHECK_FALSE(g.per_component.at(0).closed);
  CHECK(g.euler == 1);

  // A grid, a sphere and a torus side by side, merged through a soup.
  PolygonSoup all;
  for (const TriMesh& m : {test::make_open_grid(3, 3, 1.0), test::make_icosphere(1), test::make_torus(8, 6, 2, 0.5)}) {
    PolygonSoup s = to_soup(m);
    const auto base = static_cast<std::uint32_t>(all.points.size());
    const auto ibase = static_cast<std::uint32_t>(all.indices.size());
    all.points.insert(all.points.end(), s.points.begin(), s.points.end());
    for (auto i : s.indices) all.indices.push_back(base + i);
    for (std::size_t f = 1; f < s.offsets.size(); ++f) all.offsets.push_back(ibase + s.offsets[f]);
  }
  MeshSummary s = summarize(read_mesh(write_mesh(all, Format::Ply)).mesh);
  CHECK(s.components == 3);
  CHECK(s.boundary_loops == 1);
  CHECK(s.euler == 1 + 2 + 0);
  REQUIRE(s.per_component.size() == 3);
  CHECK_FALSE(s.per_component[0].closed);  // in order of lowest vertex: grid, sphere, torus
  CHECK(s.per_component[1].genus == 0);
  CHECK(s.per_component[1].closed);
  CHECK(s.per_component[2].genus == 1);
  CHECK(s.per_component[2].faces == 96);
}

TEST_CASE("Summary of a mesh 1e300 across: lengths a double holds are not overflowed squares") {
  const LoadedMesh m = read_mesh("v 0 0 0\nv 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
                                 ReadOptions{Format::Obj});
  const MeshSummary s = summarize(m.mesh);
  CHECK(s.bbox_diagonal == Approx(std::sqrt(3.0) * 1e300));
  CHECK(s.min_edge == Approx(1e300));
  CHECK(s.max_edge == Approx(std::sqrt(2.0) * 1e300));
  CHECK(std::isfinite(s.mean_edge));
  // Corners 3e308 apart: their differences overflow, and the area (1e616) is infinite, not NaN.
  const LoadedMesh far = read_mesh("v -1.5e308 0 0\nv 1.5e308 0 0\nv 0 1.5e308 0\nv 0 0 1.5e308\n"
                                   "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
                                   ReadOptions{Format::Obj});
  const MeshSummary f = summarize(far.mesh);
  CHECK(std::isinf(f.area));
  CHECK(f.area > 0);
  // The same lengths as before on an ordinary mesh.
  const MeshSummary unit = summarize(test::make_icosphere(1));
  CHECK(unit.bbox_diagonal == Approx(2 * std::sqrt(3.0)).epsilon(0.2));
  CHECK(unit.min_edge > 0);
}
