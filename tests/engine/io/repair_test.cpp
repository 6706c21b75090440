// Validation and repair: each malformed case gives its specific, located error or counted repair.
#include <catch2/catch.hpp>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "io_test_util.h"

using namespace remesh;
using Catch::Contains;

namespace {

LoadedMesh read(const std::string& bytes, ReadOptions o = {}) { return read_mesh(bytes, o); }

const Repair* find_repair(const LoadedMesh& m, const std::string& kind) {
  for (const Repair& r : m.repairs)
    if (r.kind == kind) return &r;
  return nullptr;
}

// A closed tetrahedron, consistently oriented outwards.
const std::string kTetraVerts = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
const std::string kTetraFaces = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

double signed_volume(const TriMesh& m) {
  double v = 0;
  for (auto f : m.faces()) {
    auto h = m.halfedge_handle(f);
    Vec3 a = m.point(m.from_vertex_handle(h)), b = m.point(m.to_vertex_handle(h)),
         c = m.point(m.to_vertex_handle(m.next_halfedge_handle(h)));
    v += OpenMesh::dot(a, OpenMesh::cross(b, c)) / 6;
  }
  return v;
}

}  // namespace

TEST_CASE("Empty, unreadable and unsupported input are refused") {
  CHECK_THROWS_WITH(read(""), Contains("empty input"));
  CHECK_THROWS_WITH(read("hello world, not a mesh"), Contains("unrecognised mesh format"));
  ReadOptions xyz;
  xyz.format = Format::Xyz;
  CHECK_THROWS_WITH(read("1\nc\nC 0 0 0\n", xyz), Contains("unsupported input format xyz"));
  CHECK_THROWS_AS(read_mesh_file("/nonexistent/dir/mesh.obj"), MeshError);
  CHECK_THROWS_WITH(read("v 0 0 0\nv 1 0 0\n"), Contains("no faces"));
}

TEST_CASE("Non-finite coordinates are refused with the vertex index and line") {
  CHECK_THROWS_WITH(read("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
                    Contains("vertex 1 (line 2)") && Contains("non-finite"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 inf 0\n3 0 1 2\n"),
                    Contains("vertex 2 (line 5)") && Contains("non-finite"));
  CHECK_THROWS_WITH(read("v 0 0 0\nv 1e999 0 0\nv 0 1 0\nf 1 2 3\n"), Contains("vertex 1 (line 2)"));
}

TEST_CASE("Face indices out of range are refused with the face and line") {
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 2 3\nf 1 2 9\n"),
                    Contains("face 1 (line 6)") && Contains("refers to vertex 8") && Contains("4 vertices"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
                    Contains("face 0 (line 6)") && Contains("vertex -1"));
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 2 -9\n"), Contains("OBJ line 5") && Contains("-9"));
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 0 2\n"), Contains("OBJ line 5") && Contains("index 0"));
}

TEST_CASE("Faces with fewer than 3 vertices are refused with the face and line") {
  CHECK_THROWS_WITH(read(kTetraVerts + kTetraFaces + "f 1 2\n"),
                    Contains("face 4 (line 9)") && Contains("has 2 vertices"));
  CHECK_THROWS_WITH(read("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "0 0 0\n1 0 0\n0 1 0\n1 0\n"),
                    Contains("face 0 (line 13)") && Contains("has 1 vertices"));
}

TEST_CASE("Degenerate and duplicate faces are dropped and counted") {
  const std::string obj = kTetraVerts + "v 2 0 0\n" + kTetraFaces +
                          "f 1 2 5\n"    // collinear: zero area
                          "f 1 1 2\n"    // repeated vertex
                          "f 1 2 4\n"    // exact duplicate
                          "f 4 2 1\n";   // same vertices, reversed
  LoadedMesh m = read(obj);
  CHECK(m.mesh.n_faces() == 4);
  const Repair* d = find_repair(m, "degenerate_faces_removed");
  REQUIRE(d);
  CHECK(d->count == 2);
  CHECK_THAT(d->detail, Contains("face 4 (line 10)"));
  const Repair* u = find_repair(m, "duplicate_faces_removed");
  REQUIRE(u);
  CHECK(u->count == 2);
  const Repair* r = find_repair(m, "unreferenced_vertices_removed");  // vertex 5 only had a degenerate face
  REQUIRE(r);
  CHECK(r->count == 1);
  CHECK(test::check_loaded(m.mesh).empty());
}

TEST_CASE("Unreferenced vertices are dropped and counted") {
  LoadedMesh m = read("v 9 9 9\n" + kTetraVerts + "v 8 8 8\nv 7 7 7\nf 2 4 3\nf 2 3 5\nf 3 4 5\nf 2 5 4\n");
  CHECK(m.mesh.n_vertices() == 4);
  const Repair* r = find_repair(m, "unreferenced_vertices_removed");
  REQUIRE(r);
  CHECK(r->count == 3);
  CHECK_THAT(r->detail, Contains("vertex 0"));
}

TEST_CASE("Duplicate vertices are welded only when asked") {
  // Two triangles of a square whose shared edge uses separate vertex copies.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n";
  LoadedMesh plain = read(obj);
  CHECK(plain.mesh.n_vertices() == 6);
  CHECK(summarize(plain.mesh).components == 2);
  CHECK(find_repair(plain, "vertices_welded") == nullptr);
  ReadOptions weld;
  weld.weld = true;
  LoadedMesh welded = read(obj, weld);
  CHECK(welded.mesh.n_vertices() == 4);
  MeshSummary s = summarize(welded.mesh);
  CHECK(s.components == 1);
  CHECK(s.boundary_loops == 1);
  const Repair* r = find_repair(welded, "vertices_welded");
  REQUIRE(r);
  CHECK(r->count == 2);
  CHECK(find_repair(welded, "unreferenced_vertices_removed") == nullptr);
}

TEST_CASE("A pinched vertex is split, one copy per fan, and reported") {
  // Two tetrahedra touching at vertex 1 (0-based 0).
  const std::string obj = kTetraVerts + "v 0 0 -1\nv -1 0 0\nv 0 -1 0\n" + kTetraFaces +
                          "f 1 5 6\nf 1 6 7\nf 1 7 5\nf 5 7 6\n";
  LoadedMesh m = read(obj);
  const Repair* r = find_repair(m, "nonmanifold_vertices_split");
  REQUIRE(r);
  CHECK(r->count == 1);
  CHECK_THAT(r->detail, Contains("vertex 0"));
  CHECK(m.mesh.n_vertices() == 8);
  MeshSummary s = summarize(m.mesh);
  CHECK(s.components == 2);
  CHECK(s.euler == 4);
  for (const auto& c : s.per_component) CHECK((c.closed && c.genus == 0));
  CHECK(test::check_loaded(m.mesh).empty());
}

TEST_CASE("A non-manifold edge is refused with the count and the first edge's vertices") {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
  CHECK_THROWS_WITH(read(obj), Contains("non-manifold") && Contains("1 edge is shared by more than 2 faces") &&
                                   Contains("vertices 0 and 1") && Contains("3 faces"));
}

TEST_CASE("Inconsistent orientation is fixed per component and reported") {
  LoadedMesh m = read(kTetraVerts + "f 1 3 2\nf 1 2 4\nf 4 3 2\nf 1 4 3\n" +  // third face flipped
                      "v 5 0 0\nv 6 0 0\nv 5 1 0\nv 5 0 1\nf 5 7 6\nf 5 6 8\nf 6 7 8\nf 5 8 7\n");
  const Repair* r = find_repair(m, "faces_reoriented");
  REQUIRE(r);
  CHECK(r->count == 1);
  CHECK_THAT(r->detail, Contains("1 component"));
  CHECK(signed_volume(m.mesh) > 0);  // the majority (outward) orientation was kept
  CHECK(summarize(m.mesh).boundary_loops == 0);
}

TEST_CASE("A Moebius strip is refused as non-orientable") {
  std::string obj;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n, w = 0.3;
    for (int s : {-1, 1}) {
      const double r = 1 + s * w * std::cos(t / 2);
      obj += "v " + std::to_string(r * std::cos(t)) + " " + std::to_string(r * std::sin(t)) + " " +
             std::to_string(s * w * std::sin(t / 2)) + "\n";
    }
  }
  for (int i = 0; i < n; ++i) {
    int a = 2 * i + 1, b = 2 * i + 2, c = 2 * ((i + 1) % n) + 1, d = 2 * ((i + 1) % n) + 2;
    if (i == n - 1) std::swap(c, d);  // the half twist
    obj += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
    obj += "f " + std::to_string(b) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
  }
  CHECK_THROWS_WITH(read(obj), Contains("non-orientable"));
}

TEST_CASE("A mesh with no face left after repair is refused") {
  CHECK_THROWS_WITH(read("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 3 2 1\n"), Contains("no surface is left"));
}

TEST_CASE("Several components and boundaries are fine") {
  LoadedMesh m = read("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n");
  MeshSummary s = summarize(m.mesh);
  CHECK(s.components == 2);
  CHECK(s.boundary_loops == 2);
  CHECK(m.repairs.empty());
}

TEST_CASE("max_faces is enforced before allocating, with LimitError") {
  ReadOptions o;
  o.max_faces = 3;
  CHECK_THROWS_AS(read(kTetraVerts + kTetraFaces, o), LimitError);
  CHECK_THROWS_AS(read("OFF\n4 4000000000 0\n", o), LimitError);
  CHECK_THROWS_AS(read("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                       "property float z\nelement face 99999999\nproperty list uchar int vertex_indices\nend_header\n", o),
                  LimitError);
  std::string stl(84, '\0');
  stl[80] = '\x10';  // 16 triangles claimed
  ReadOptions stl_o = o;
  stl_o.format = Format::Stl;
  CHECK_THROWS_AS(read(stl, stl_o), LimitError);
  // Polygons count after triangulation too.
  CHECK_THROWS_AS(read("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 1 0\nv -1 0 0\nf 1 2 3 4 5 6\n", o), LimitError);
  o.max_faces = 4;
  CHECK_NOTHROW(read(kTetraVerts + kTetraFaces, o));
}

TEST_CASE("Headers claiming huge counts are refused without allocating") {
  CHECK_THROWS_WITH(read("OFF\n2147483647 2147483647 0\n0 0 0\n"), Contains("header claims") && Contains("2147483647"));
  CHECK_THROWS_WITH(read("ply\nformat binary_little_endian 1.0\nelement vertex 2147483647\nproperty double x\n"
                         "property double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\n"
                         "end_header\n0000"),
                    Contains("header claims") && Contains("vertex"));
  std::string stl(84 + 50, '\0');
  stl[83] = '\x7f';
  ReadOptions o;
  o.format = Format::Stl;
  CHECK_THROWS_WITH(read(stl, o), Contains("header says") && Contains("truncated"));
  std::string off = "OFF BINARY\n";
  for (int i = 0; i < 2; ++i) off += std::string("\x7f\xff\xff\xff", 4);
  off += std::string(4, '\0');
  CHECK_THROWS_WITH(read(off), Contains("header claims"));
}

TEST_CASE("Malformed text names the line") {
  CHECK_THROWS_WITH(read("v 0 0 0\nv 1 zero 0\n"), Contains("OBJ line 2") && Contains("'zero'"));
  CHECK_THROWS_WITH(read("v 0 0\n"), Contains("OBJ line 1") && Contains("fewer than 3"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"), Contains("OFF line 6") && Contains("declares 4"));
  CHECK_THROWS_WITH(read("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"), Contains("STL line 4"));
  CHECK_THROWS_WITH(read("ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n"),
                    Contains("PLY header line 4") && Contains("flot"));
}

TEST_CASE("Text files cut inside their last line are refused as truncated") {
  // Cutting "f 1 2 3" or "3 0 1 2" inside a number leaves a well-formed but wrong face: refuse.
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4"), Contains("OBJ line 8") && Contains("truncated"));
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3"), Contains("truncated"));
  CHECK_NOTHROW(read(kTetraVerts + kTetraFaces + "# trailing comment without a line break"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2"), Contains("OFF line 6") && Contains("truncated"));
  CHECK_NOTHROW(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 2";
  CHECK_THROWS_WITH(read(ply), Contains("PLY line 13") && Contains("truncated"));
  CHECK_NOTHROW(read(ply + "\n"));
  CHECK_THROWS_WITH(read("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                         "endloop\nendfacet\n"),
                    Contains("endsolid"));
}

TEST_CASE("Welding stops where it would make an edge non-manifold") {
  // Three separate triangles whose spine edges coincide (a book with three pages), plus a square
  // split along a seam of duplicated vertices: only the seam is welded.
  const std::string obj =
      "v 0 0 0\nv 0 0 1\nv 1 0 0\n"
      "v 0 0 0\nv 0 0 1\nv 0 1 0\n"
      "v 0 0 0\nv 0 0 1\nv -1 -1 0\n"
      "v 5 0 0\nv 6 0 0\nv 6 1 0\nv 5 0 0\nv 6 1 0\nv 5 1 0\n"
      "f 1 2 3\nf 4 5 6\nf 7 8 9\nf 10 11 12\nf 13 14 15\n";
  ReadOptions weld;
  weld.weld = true;
  LoadedMesh m = read(obj, weld);
  const Repair* r = find_repair(m, "vertices_welded");
  REQUIRE(r);
  CHECK(r->count == 2);  // the seam's two duplicates; the book's spine stays apart
  MeshSummary s = summarize(m.mesh);
  CHECK(s.components == 4);
  CHECK(m.mesh.n_faces() == 5);
  CHECK(test::check_loaded(m.mesh).empty());
}
