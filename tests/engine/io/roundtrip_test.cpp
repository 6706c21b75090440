// Write then read back in every format: same connectivity, positions exact (or float32 for STL/GLB).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "io_test_util.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

using Key = std::array<double, 9>;

/// Every face as its corner positions, rotated to start at the smallest (orientation kept),
/// optionally rounded to float32; sorted. Equal keys = same faces, same orientation, same points.
std::vector<Key> face_keys(const TriMesh& m, bool to_float) {
  std::vector<Key> keys;
  for (auto f : m.faces()) {
    std::array<std::array<double, 3>, 3> p;
    std::size_t i = 0;
    for (auto v : m.fv_range(f)) {
      const Vec3 q = m.point(v);
      for (std::size_t d = 0; d < 3; ++d) {
        // volatile: GCC 12 at -O3 vectorises this loop and drops the double->float->double rounding.
        const volatile float rounded = static_cast<float>(q[static_cast<int>(d)]);
        p[i][d] = to_float ? static_cast<double>(rounded) : q[static_cast<int>(d)];
      }
      ++i;
    }
    const std::size_t s = static_cast<std::size_t>(std::min_element(p.begin(), p.end()) - p.begin());
    Key k;
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t d = 0; d < 3; ++d) k[3 * c + d] = p[(s + c) % 3][d];
    keys.push_back(k);
  }
  std::sort(keys.begin(), keys.end());
  return keys;
}

bool is_float_format(Format f) { return f == Format::Stl || f == Format::Glb; }

}  // namespace

TEST_CASE("Triangle meshes round-trip through every format") {
  std::vector<std::pair<std::string, TriMesh>> meshes;
  meshes.emplace_back("icosphere", test::make_icosphere(2, 1.7));
  meshes.emplace_back("torus", test::make_torus(12, 8, 2.0, 0.5));
  meshes.emplace_back("open grid", test::make_open_grid(5, 4, 0.3));
  for (auto& [name, mesh] : meshes) {
    for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Glb}) {
      INFO(name << " as " << format_name(f));
      const std::string bytes = write_mesh(mesh, f);
      CHECK(detect_format(bytes) == f);
      LoadedMesh back = read_mesh(bytes);
      CHECK(back.repairs.empty());
      CHECK(back.mesh.n_vertices() == mesh.n_vertices());
      CHECK(back.mesh.n_faces() == mesh.n_faces());
      CHECK(face_keys(back.mesh, is_float_format(f)) == face_keys(mesh, is_float_format(f)));
      if (!is_float_format(f)) {  // indexed formats keep the vertex order too
        bool same_points = true;
        for (auto v : mesh.vertices()) same_points &= back.mesh.point(v) == mesh.point(v);
        CHECK(same_points);
      }
    }
  }
}

TEST_CASE("Exact positions survive text formats, including awkward doubles") {
  TriMesh m;
  auto a = m.add_vertex(Vec3(0.1, 1.0 / 3.0, -2.5e-8));
  auto b = m.add_vertex(Vec3(12345.678901234567, -0.0, 3e-5));
  auto c = m.add_vertex(Vec3(7.0000000000000009, 1.0000000000000002, 2.2250738585072014e-308));
  m.add_face(a, b, c);
  for (Format f : {Format::Obj, Format::Off, Format::Ply}) {
    LoadedMesh back = read_mesh(write_mesh(m, f));
    for (int i = 0; i < 3; ++i) CHECK(back.mesh.point(TriMesh::VertexHandle(i)) == m.point(TriMesh::VertexHandle(i)));
  }
}

TEST_CASE("Polygon soups keep their polygons in OBJ, OFF and PLY, GLB adds a LINES primitive") {
  // A cube of quads plus a hexagonal cap elsewhere.
  PolygonSoup soup = test::make_soup(
      {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
      {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}});
  const std::string off = write_mesh(soup, Format::Off);
  CHECK(off.rfind("OFF\n8 6 0\n", 0) == 0);
  CHECK(off.find("\n4 0 3 2 1\n") != std::string::npos);
  CHECK(write_mesh(soup, Format::Obj).find("\nf 1 4 3 2\n") != std::string::npos);
  for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Glb}) {
    INFO(format_name(f));
    LoadedMesh back = read_mesh(write_mesh(soup, f));
    CHECK(back.mesh.n_faces() == 12);
    CHECK(summarize(back.mesh).euler == 2);
    const bool polygons_kept = f == Format::Obj || f == Format::Off || f == Format::Ply;
    CHECK((!back.repairs.empty() && back.repairs[0].kind == "polygons_triangulated") == polygons_kept);
    if (polygons_kept) CHECK(back.repairs[0].count == 6);
  }
  const std::string glb = write_mesh(soup, Format::Glb);
  CHECK(glb.find(R"("mode":1)") != std::string::npos);  // LINES with the 12 cube edges
  CHECK(glb.find(R"("componentType":5125,"count":24,)") != std::string::npos);
  CHECK(write_mesh(test::make_icosphere(1), Format::Glb).find(R"("mode":1)") == std::string::npos);
}

TEST_CASE("XYZ writes one carbon atom per point") {
  PolygonSoup soup = to_soup(test::make_icosphere(1));
  const std::string xyz = write_mesh(soup, Format::Xyz);
  const char* p = xyz.c_str();
  char* end = nullptr;
  CHECK(std::strtoul(p, &end, 10) == soup.points.size());
  std::size_t line_start = xyz.find('\n', xyz.find('\n') + 1) + 1;
  std::size_t atoms = 0;
  bool exact = true;
  while (line_start < xyz.size()) {
    CHECK(xyz.compare(line_start, 2, "C ") == 0);
    p = xyz.c_str() + line_start + 2;
    for (int k = 0; k < 3; ++k) {
      exact &= std::strtod(p, &end) == soup.points[atoms][k];
      p = end;
    }
    ++atoms;
    line_start = xyz.find('\n', line_start) + 1;
    if (line_start == 0) break;
  }
  CHECK(atoms == soup.points.size());
  CHECK(exact);
}

TEST_CASE("Files: the extension chooses the format, unknown extensions are refused") {
  const auto dir = std::filesystem::temp_directory_path() / ("remesh_io_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  PolygonSoup soup = to_soup(test::make_torus(8, 6, 2, 0.7));
  for (const char* ext : {"obj", "off", "ply", "stl", "glb", "gltf"}) {
    const std::string path = (dir / (std::string("t.") + ext)).string();
    write_mesh_file(soup, path);
    LoadedMesh back = read_mesh_file(path);
    CHECK(back.mesh.n_faces() == 96);
    CHECK(summarize(back.mesh).per_component.at(0).genus == 1);
  }
  CHECK_THROWS_AS(write_mesh_file(soup, (dir / "t.docx").string()), MeshError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("The bundled sample mesh reads as a closed sphere") {
  LoadedMesh m = read_mesh_file(std::string(REMESH_TEST_DATA_DIR) + "/tetra_sphere.obj");
  MeshSummary s = summarize(m.mesh);
  CHECK(m.repairs.empty());
  CHECK(s.faces >= 200);
  CHECK(s.euler == 2);
  CHECK(s.boundary_loops == 0);
}
