// Tests of the test generators themselves: the topology they claim is the topology they build.
#include <catch2/catch.hpp>

#include "support/mesh_generators.h"

using namespace remesh::test;

TEST_CASE("generated meshes have the topology they claim", "[support]") {
  struct Case { const char* name; remesh::TriMesh mesh; long euler; std::size_t loops; };
  Case cases[] = {
      {"icosphere", make_icosphere(2), 2, 0},
      {"torus", make_torus(24, 12, 2.0, 0.6), 0, 0},
      {"open grid", make_open_grid(6, 5, 1.0), 1, 1},
      {"hex patch", make_hex_lattice_patch(7, 8, 1.0), 1, 1},
      {"double torus", make_double_torus(), -2, 0},
      {"plate with 3 holes", make_plate_with_holes(3, 1.0, 1), -4, 0},
  };
  for (auto& c : cases) {
    INFO(c.name);
    CHECK(check_mesh_valid(c.mesh).empty());
    CHECK(euler_characteristic(c.mesh) == c.euler);
    CHECK(count_boundary_loops(c.mesh) == c.loops);
    CHECK(count_components(c.mesh) == 1);
  }
}

TEST_CASE("hex lattice patch interior vertices have valence 6", "[support]") {
  auto m = make_hex_lattice_patch(9, 9, 1.0);
  std::size_t interior = 0;
  for (auto v : m.vertices()) {
    if (m.is_boundary(v)) continue;
    ++interior;
    CHECK(m.valence(v) == 6);
  }
  CHECK(interior > 20);
}

TEST_CASE("check_mesh_valid finds a folded pair", "[support]") {
  auto m = make_open_grid(2, 1, 1.0);
  // Push one vertex through the plane far enough to fold a triangle over its neighbour.
  for (auto v : m.vertices())
    if (m.point(v)[0] == 1.0 && m.point(v)[1] == 0.0) m.point(v) = remesh::Vec3(1.0, 5.0, 0.0);
  CHECK_FALSE(check_mesh_valid(m).empty());
}
