// free_mesh (core/mesh.h): the mesh's memory is returned and the mesh can be built again.
#include <catch2/catch.hpp>

#include <malloc.h>

#include <cstddef>
#include <vector>

#include "core/mesh.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

/// Bytes the allocator has handed out and not had back (glibc).
std::size_t bytes_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

}  // namespace

TEST_CASE("free_mesh returns the memory of the elements as well as of the properties", "[core]") {
  const std::size_t before = bytes_in_use();
  TriMesh mesh = test::make_icosphere(6);  // 40 962 vertices, ~10 MB
  const std::size_t built = bytes_in_use();
  REQUIRE(built > before + (4u << 20));
  free_mesh(mesh);
  CHECK(mesh.n_vertices() == 0);
  CHECK(mesh.n_faces() == 0);
  // Assigning a new mesh alone keeps the element arrays, about half of it (checked: this fails).
  CHECK(bytes_in_use() < before + (built - before) / 10);
  // Built again, with the traits' attributes (status, normals) in place.
  const TriMesh sphere = test::make_icosphere(2);
  for (auto v : sphere.vertices()) mesh.add_vertex(sphere.point(v));
  for (auto f : sphere.faces()) {
    std::vector<OpenMesh::VertexHandle> corners;
    for (auto v : sphere.fv_range(f)) corners.push_back(mesh.vertex_handle(static_cast<unsigned>(v.idx())));
    REQUIRE(mesh.add_face(corners).is_valid());
  }
  CHECK(mesh.has_vertex_status());
  CHECK(mesh.has_face_normals());
  CHECK(test::check_mesh_valid(mesh) == "");
}
