// Validation and repair: each malformed case gives its specific, located error or counted repair.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "io/mesh_io.h"
#include "io/parse_util.h"
#include "io/summary.h"
#include "io_test_util.h"
#include "support/mesh_generators.h"

using namespace remesh;
using Catch::Contains;
using Catch::StartsWith;

namespace {

LoadedMesh read(const std::string& bytes, ReadOptions o = {}) { return read_mesh(bytes, o); }

/// What reading throws, named by its type ("MeshError: ...", "LimitError: ..."); "" if it reads.
/// LimitError is not a MeshError: the type decides the HTTP status (413 or 422).
std::string error_of(const std::string& bytes, const ReadOptions& o) {
  try {
    read_mesh(bytes, o);
  } catch (const LimitError& e) {
    return std::string("LimitError: ") + e.what();
  } catch (const MeshError& e) {
    return std::string("MeshError: ") + e.what();
  }
  return "";
}

/// A GLB tetrahedron: 4 positions, then an index accessor of `index_count` unsigned shorts in a
/// bufferView that holds its 12. With `nan_at` (0-11), that coordinate of the positions is NaN.
std::string tetra_glb(std::size_t index_count, int nan_at = -1) {
  std::string bin;
  int k = 0;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f}) {
    if (k++ == nan_at) v = std::numeric_limits<float>::quiet_NaN();
    bin.append(reinterpret_cast<const char*>(&v), 4);
  }
  for (std::uint16_t i : {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}) bin.append(reinterpret_cast<const char*>(&i), 2);
  std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
    "buffers":[{"byteLength":72}],
    "bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":24}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},
                 {"bufferView":1,"componentType":5123,"count":)" + std::to_string(index_count) +
                     R"(,"type":"SCALAR"}]})";
  while (json.size() % 4) json.push_back(' ');
  std::string out = "glTF";
  auto put32 = [&](std::size_t v) {
    const auto u = static_cast<std::uint32_t>(v);
    out.append(reinterpret_cast<const char*>(&u), 4);
  };
  put32(2);
  put32(12 + 8 + json.size() + 8 + bin.size());
  put32(json.size());
  out += "JSON" + json;
  put32(bin.size());
  out += std::string("BIN\0", 4) + bin;
  return out;
}

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

/// "v x y z\n" with every digit: the points read back exactly.
std::string obj_vertex(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
  return buf;
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
  // glTF: the coordinate as stored, before the node transform spreads the NaN ("(nan, nan, nan)").
  CHECK_THROWS_WITH(read_mesh(tetra_glb(12, 4)), Contains("POSITION element 1 has a non-finite coordinate (1, nan, 0)"));
}

TEST_CASE("Numbers nearer 0 than any double read as the nearest one, numbers past the largest are refused") {
  // A tetrahedron in each text format, its corner (1, y, 0) with y as written.
  auto tetra = [](const std::string& y) {
    const std::string p[4] = {"0 0 0", "1 " + y + " 0", "0 1 0", "0 0 1"};
    const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
    std::string obj, off = "OFF\n4 4 0\n", ply, stl = "solid t\n";
    ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
          "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
    for (const std::string& q : p) {
      obj += "v " + q + "\n";
      off += q + "\n";
      ply += q + "\n";
    }
    const std::string records = "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";  // kTetraFaces from 0
    for (const auto& f : faces) {
      stl += "facet normal 0 0 0\nouter loop\n";
      for (int k : f) stl += "vertex " + p[k] + "\n";
      stl += "endloop\nendfacet\n";
    }
    return std::vector<std::string>{obj + kTetraFaces, off + records, ply + records, stl + "endsolid t\n"};
  };
  const double tiny = std::numeric_limits<double>::denorm_min();
  const std::pair<const char*, double> underflows[] = {
      {"1e-330", 0.0}, {"-1e-330", -0.0}, {"0.0001e-321", 0.0}, {"123456789e-340", 0.0},
      {"2.4703282292062327e-324", 0.0},  // just under half the smallest denormal
      {"2.4703282292062328e-324", tiny}, {"1e-310", 1e-310}, {"-4e-324", -tiny}};
  for (const auto& [text, want] : underflows)
    for (const std::string& file : tetra(text)) {
      CAPTURE(file);
      const LoadedMesh m = read(file);
      REQUIRE(m.mesh.n_faces() == 4);
      int found = 0;
      for (auto v : m.mesh.vertices()) {
        const Vec3 q = m.mesh.point(v);
        if (q[0] != 1) continue;
        ++found;
        CHECK(q[1] == want);
        CHECK(std::signbit(q[1]) == std::signbit(want));
      }
      CHECK(found == 1);
    }
  for (const char* text : {"1e400", "-1e400", "1.7976931348623159e308", "100e307"})
    for (const std::string& file : tetra(text))
      CHECK_THROWS_WITH(read(file), Contains(std::string("'") + text + "'") && Contains(" line ") &&
                                        Contains("(too large: the largest double is about 1.8e308)"));
  // "inf" is no number out of range: non-finite, as before.
  CHECK_THROWS_WITH(read(tetra("inf")[0]),
                    Contains("vertex 1 (line 2) has a non-finite coordinate (1, inf, 0)"));
  // At the edge of the range, the parsing the readers share: the largest double, as written and
  // written above it where it still rounds down to it, reads; just past that is too large.
  const double largest = std::numeric_limits<double>::max();
  for (const char* text :
       {"1.7976931348623157e308", "1.7976931348623158e308", "+0.0017976931348623157e311"}) {
    double v = 0;
    CHECK(io::parse_double(text, v));
    CHECK(v == largest);
  }
  double v = 0;
  CHECK(!io::parse_double("-1.7976931348623159e308", v));
  CHECK(io::too_large_note("-1.7976931348623159e308") != "");
  for (const char* text : {"1e-400", "inf", "abc", "1e400x", "1e"}) CHECK(io::too_large_note(text) == "");
}

TEST_CASE("Face indices out of range are refused with the face and line") {
  CHECK_THROWS_WITH(read(kTetraVerts + "f 1 2 3\nf 1 2 9\n"),
                    Contains("face 1 (line 6)") && Contains("refers to vertex 9,") && Contains("4 vertices") &&
                        Contains("OBJ counts from 1"));  // the index as the file has it (it said 8)
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
                    Contains("face 0 (line 6)") && Contains("vertex -1") && Contains("0-based"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"), Contains("refers to vertex 3,"));
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

TEST_CASE("Faces with a repeated vertex, zero-area faces on an edge with 2 other faces and duplicates are dropped") {
  // The tetrahedron with its face 2 3 4 split at the middle of edge 2-3 and a cap over that point
  // (repaired), then the faces to drop.
  const std::string obj = kTetraVerts + "v 2 0 0\nv 0.5 0.5 0\n" +
                          "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 6 3 4\nf 2 6 4\n"
                          "f 2 3 6\n"    // the cap, zero area
                          "f 1 2 5\n"    // collinear, on edge 1-2 with its 2 faces: would make a third
                          "f 1 1 2\n"    // repeated vertex
                          "f 1 2 4\n"    // exact duplicate
                          "f 4 2 1\n";   // same vertices, reversed
  LoadedMesh m;
  REQUIRE_NOTHROW(m = read(obj));
  const Repair* d = find_repair(m, "degenerate_faces_removed");
  REQUIRE(d);
  CHECK(d->count == 2);
  CHECK_THAT(d->detail, Contains("1 with a repeated vertex (first: face 7 (line 14))") &&
                            Contains("1 of zero area") && Contains("face 6 (line 13)") && Contains("--weld"));
  const Repair* c = find_repair(m, "degenerate_faces_repaired");  // the cap: dropping the other kept it
  REQUIRE(c);
  CHECK(c->count == 1);
  CHECK_THAT(c->detail, Contains("face 5 (line 12)") && Contains("1 flip"));
  const Repair* u = find_repair(m, "duplicate_faces_removed");
  REQUIRE(u);
  CHECK(u->count == 2);
  const Repair* r = find_repair(m, "unreferenced_vertices_removed");  // vertex 5 only had a dropped face
  REQUIRE(r);
  CHECK(r->count == 1);
  CHECK(test::check_loaded(m.mesh).empty());
  CHECK(m.mesh.n_faces() == 6);
  CHECK(test::euler_characteristic(m.mesh) == 2);
  CHECK(test::count_boundary_loops(m.mesh) == 0);
}

TEST_CASE("Zero-area faces that would make a surface non-orientable are dropped and it reads") {
  // A band whose ends meet with a half twist at separate, coincident vertices (open, orientable),
  // closed into a Moebius strip by two needles across the seam: kept, the strip could not be
  // oriented. Without them it reads, as it did before zero-area faces were kept.
  std::string obj;
  const int n = 12;
  for (int i = 0; i <= n; ++i) {
    const double t = 2 * M_PI * i / n, w = 0.3;
    for (int s : {-1, 1}) {
      const double r = 1 + s * w * std::cos(t / 2);
      obj += obj_vertex(Vec3(r * std::cos(t), r * std::sin(t), s * w * std::sin(t / 2)));
    }
  }
  for (int i = 0; i < n; ++i) {
    const int a = 2 * i + 1, b = 2 * i + 2, c = 2 * i + 3, d = 2 * i + 4;
    obj += "f " + std::to_string(a) + " " + std::to_string(c) + " " + std::to_string(b) + "\n";
    obj += "f " + std::to_string(b) + " " + std::to_string(c) + " " + std::to_string(d) + "\n";
  }
  const int a0 = 1, b0 = 2, an = 2 * n + 1, bn = 2 * n + 2;  // an at b0's position, bn at a0's
  obj += "f " + std::to_string(a0) + " " + std::to_string(b0) + " " + std::to_string(an) + "\n";
  obj += "f " + std::to_string(a0) + " " + std::to_string(an) + " " + std::to_string(bn) + "\n";
  LoadedMesh m;
  REQUIRE_NOTHROW(m = read(obj));
  const Repair* d = find_repair(m, "degenerate_faces_removed");
  REQUIRE(d);
  CHECK(d->count == 2);
  CHECK(m.mesh.n_faces() == 2 * n);
  CHECK(test::check_loaded(m.mesh).empty());
  CHECK(test::count_boundary_loops(m.mesh) == 1);
}

TEST_CASE("A zero-area face no operation repairs is dropped with a warning that names --weld") {
  // A lone collinear triangle beside a tetrahedron: removing it would remove its component.
  LoadedMesh m = read(kTetraVerts + kTetraFaces + "v 5 0 0\nv 6 0 0\nv 7 0 0\nf 5 6 7\n");
  const Repair* d = find_repair(m, "degenerate_faces_removed");
  REQUIRE(d);
  CHECK(d->count == 1);
  CHECK_THAT(d->detail, Contains("face 4 (line 12)") && Contains("hole") && Contains("--weld / weld=true") &&
                            Contains("3 vertices unused"));
  CHECK(m.mesh.n_faces() == 4);
  CHECK(m.mesh.n_vertices() == 4);
  CHECK(test::check_loaded(m.mesh).empty());
  // The same 1e-14 across, far from the origin: its edges are measured, not its points (scaled
  // points carry rounding of 1e-16 of their size into it).
  const Vec3 p(0.1, 0.9, -0.4), step(std::ldexp(1.0, -46), std::ldexp(1.0, -46), std::ldexp(1.0, -47));
  LoadedMesh tiny = read(kTetraVerts + kTetraFaces + obj_vertex(p) + obj_vertex(p + step) +
                         obj_vertex(p + 2 * step) + "f 5 6 7\n");
  CHECK(tiny.mesh.n_faces() == 4);
  CHECK(test::check_loaded(tiny.mesh).empty());
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
  // Header counts over the limit that the bytes can hold (the same tetrahedron).
  CHECK_THROWS_AS(read("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n", o),
                  LimitError);
  std::string stl(84 + 50 * 16, '\0');
  stl[80] = '\x10';  // 16 triangles claimed, and there
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

TEST_CASE("With max_faces set, counts the bytes cannot hold are malformed (MeshError), not over the limit") {
  // The service sets max_faces and answers LimitError with 413: a 42 KB OFF uploaded as .stl (its
  // text read as a binary STL's triangle count, 808263728) was called too large, not malformed.
  ReadOptions o;
  o.max_faces = 2'000'000;  // remeshd's default
  auto stl_count = [](const std::string& bytes) {
    std::uint32_t n = 0;
    for (int i = 3; i >= 0; --i) n = n << 8 | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(i)]);
    return n;
  };
  SECTION("binary STL") {
    o.format = Format::Stl;
    const std::string off = write_mesh(test::make_icosphere(3), Format::Off);
    const std::uint32_t n = stl_count(off);
    REQUIRE(n > o.max_faces);
    CHECK_THAT(error_of(off, o), StartsWith("MeshError: binary STL: header says " + std::to_string(n) + " triangles") &&
                                     Contains("the file has " + std::to_string(off.size()) + " bytes"));
    std::mt19937 rng(5);
    std::string noise(5000, '\0');
    for (char& c : noise) c = static_cast<char>(rng());
    noise[0] = 'x';  // not "solid"
    REQUIRE(stl_count(noise) > o.max_faces);
    CHECK_THAT(error_of(noise, o), StartsWith("MeshError: binary STL: header says " + std::to_string(stl_count(noise))));
    std::string three(84 + 50 * 3, '\0');  // 3 000 000 triangles claimed, 3 there
    three.replace(80, 3, "\xc0\xc6\x2d");  // little-endian 0x2dc6c0
    CHECK_THAT(error_of(three, o), StartsWith("MeshError: binary STL: header says 3000000 triangles") &&
                                       Contains("the file has 234 bytes"));
  }
  SECTION("OFF, ASCII and binary") {
    CHECK_THAT(error_of("OFF\n999999999 999999999 0\n0 0 0\n", o),
               StartsWith("MeshError: OFF header claims 999999999 vertices and 999999999 faces") &&
                   Contains("only 6 bytes follow"));
    CHECK_THAT(error_of("OFF\n4 4000000000 0\n", o), StartsWith("MeshError: OFF header claims") && Contains("4000000000 faces"));
    std::string off = "OFF BINARY\n";
    for (std::uint32_t v : {3u, 100'000'000u, 0u})
      for (int shift = 24; shift >= 0; shift -= 8) off.push_back(static_cast<char>(v >> shift));
    off += std::string(36, '\0');  // the 3 vertices
    CHECK_THAT(error_of(off, o), StartsWith("MeshError: OFF header claims 3 vertices and 100000000 faces"));
  }
  SECTION("PLY, ASCII and binary") {
    const std::string header = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 99999999\nproperty list uchar int vertex_indices\nend_header\n";
    CHECK_THAT(error_of("ply\nformat ascii 1.0\n" + header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", o),
               StartsWith("MeshError: PLY header claims 99999999 'face' elements"));
    std::string body(36, '\0');  // 3 vertices, then one face
    body += std::string("\x03\0\0\0\0\x01\0\0\0\x02\0\0\0", 13);
    CHECK_THAT(error_of("ply\nformat binary_little_endian 1.0\n" + header + body, o),
               StartsWith("MeshError: PLY header claims 99999999 'face' elements"));
  }
  SECTION("GLB: an index accessor longer than its bufferView") {
    // The face limit counts triangles as they are taken from a checked accessor: already in order.
    CHECK_THAT(error_of(tetra_glb(3'000'000), o), StartsWith("MeshError: glTF:") && Contains("3000000 elements") &&
                                                      Contains("reaches past the end of its bufferView"));
  }
}

TEST_CASE("With max_faces set, a file that holds more faces than the limit is refused with LimitError") {
  // Every format and variant, with the faces really there: one over the limit is refused, at the
  // limit it reads.
  const PolygonSoup soup = to_soup(test::make_icosphere(3));
  const std::size_t faces = soup.offsets.size() - 1;
  for (const test::SampleFile& file : test::sample_files(soup)) {
    INFO(file.name);
    ReadOptions o;
    o.format = file.format;
    o.max_faces = faces - 1;
    CHECK_THAT(error_of(file.bytes, o), StartsWith("LimitError: ") && Contains(std::to_string(faces - 1) + " faces"));
    o.max_faces = faces;
    CHECK(error_of(file.bytes, o).empty());
  }
  // A binary STL of 2001 (degenerate) triangles, its size exactly 84 + 50 n: over the limit before
  // anything is read.
  std::string stl(84 + 50 * 2001, '\0');
  stl.replace(80, 2, "\xd1\x07");  // little-endian 0x07d1
  ReadOptions o;
  o.format = Format::Stl;
  o.max_faces = 2000;
  CHECK(error_of(stl, o) == "LimitError: STL has more than 2000 faces (the limit); found at least 2001");
  // glTF counts triangles as it takes them from checked accessors.
  ReadOptions glb_o;
  glb_o.max_faces = 4;
  CHECK(error_of(tetra_glb(12), glb_o).empty());  // the helper's GLB is a closed tetrahedron
  glb_o.max_faces = 3;
  CHECK_THAT(error_of(tetra_glb(12), glb_o), StartsWith("LimitError: glTF has more than 3 faces"));
}

TEST_CASE("Malformed text names the line") {
  CHECK_THROWS_WITH(read("v 0 0 0\nv 1 zero 0\n"), Contains("OBJ line 2") && Contains("'zero'"));
  CHECK_THROWS_WITH(read("v 0 0\n"), Contains("OBJ line 1") && Contains("fewer than 3"));
  CHECK_THROWS_WITH(read("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n"), Contains("OFF line 6") && Contains("declares 4"));
  CHECK_THROWS_WITH(read("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"), Contains("STL line 4"));
  CHECK_THROWS_WITH(read("ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n"),
                    Contains("PLY header line 4") && Contains("flot"));
}

TEST_CASE("A text file's last line needs no line break, and OFF and PLY cut short are refused by their counts") {
  // Files joined with '\n' between lines end without one; every other mesh tool reads them.
  const std::string obj = kTetraVerts + kTetraFaces;
  const std::string off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  for (const std::string& text : {obj, off, ply}) {
    const LoadedMesh want = read(text);
    REQUIRE(want.mesh.n_faces() == 4);
    for (const std::string end : {"", "\r", " \t"}) {
      const std::string unended = text.substr(0, text.size() - 1) + end;
      CAPTURE(unended);
      test::check_same_mesh(read(unended), want);
    }
  }
  CHECK_NOTHROW(read(obj + "# trailing comment without a line break"));
  // OFF and PLY declare their counts: a file cut inside or before its last record is refused.
  CHECK_THROWS_WITH(read(off.substr(0, off.size() - 3)),
                    Contains("OFF line 10") && Contains("declares 3 vertices but the file ends after 2"));
  CHECK_THROWS_WITH(read(off.substr(0, off.size() - 8)), Contains("file ends after 3 of 4 faces"));
  CHECK_THROWS_WITH(read(ply.substr(0, ply.size() - 3)), Contains("PLY line 17: bad list length 3 in face 3"));
  // OBJ declares none: a cut that leaves a face of 2 corners is refused as such.
  CHECK_THROWS_WITH(read(obj.substr(0, obj.size() - 3)), Contains("face 3 (line 8) has 2 vertices"));
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

// Zero-area faces repaired without opening the surface: closed meshes stay closed, open ones keep
// their boundary loops, over a set of meshes (closed genus 0, 1, 2 and open).
namespace {

struct Edited {
  std::vector<Vec3> points;
  std::vector<std::vector<std::uint32_t>> faces;
  std::size_t zero_area = 0;  ///< zero-area faces added
};

Edited faces_of(const TriMesh& mesh) {
  Edited e;
  for (auto v : mesh.vertices()) e.points.push_back(mesh.point(v));
  for (auto f : mesh.faces()) {
    auto& face = e.faces.emplace_back();
    for (auto v : mesh.fv_range(f)) face.push_back(static_cast<std::uint32_t>(v.idx()));
  }
  return e;
}

/// Vertices, boundary or interior, whose one-rings do not touch: edits at each stay apart.
std::vector<TriMesh::VertexHandle> spread_vertices(const TriMesh& mesh, bool interior, std::size_t count) {
  std::vector<bool> near(mesh.n_vertices(), false);
  std::vector<TriMesh::VertexHandle> out;
  for (auto v : mesh.vertices()) {
    if (out.size() == count) break;
    if (near[v.idx()] || (interior && mesh.is_boundary(v))) continue;
    bool free = true;
    for (auto w : mesh.vv_range(v)) free = free && !near[w.idx()];
    if (!free) continue;
    out.push_back(v);
    for (auto w : mesh.vv_range(v)) {
      near[w.idx()] = true;
      for (auto x : mesh.vv_range(w)) near[x.idx()] = true;
    }
    near[v.idx()] = true;
  }
  return out;
}

/// How far a vertex's copy is from it.
enum class Offset { None, Relative, AlongEdge };

/// Splits interior vertex v into v and a copy (at v, 1e-14 of v's position away, or 2e-12 of the
/// edge to its first neighbour along it), each taking half of its fan, and closes the slit between
/// them with two needle triangles.
void add_needles(const TriMesh& mesh, TriMesh::VertexHandle v, Offset offset, Edited& e) {
  std::vector<TriMesh::HalfedgeHandle> fan;  // outgoing, counter-clockwise
  for (auto h : mesh.voh_ccw_range(v)) fan.push_back(h);
  const auto copy = static_cast<std::uint32_t>(e.points.size());
  const Vec3 p = mesh.point(v), along = mesh.point(mesh.to_vertex_handle(fan[0])) - p;
  e.points.push_back(offset == Offset::None       ? p
                     : offset == Offset::Relative ? p * (1 + 1e-14)
                                                  : p + along * 2e-12);
  const std::size_t half = fan.size() / 2;
  for (std::size_t i = half; i < fan.size(); ++i)
    for (auto& c : e.faces[mesh.face_handle(fan[i]).idx()])
      if (c == static_cast<std::uint32_t>(v.idx())) c = copy;
  const auto vi = static_cast<std::uint32_t>(v.idx());
  const auto w0 = static_cast<std::uint32_t>(mesh.to_vertex_handle(fan[0]).idx());
  const auto wh = static_cast<std::uint32_t>(mesh.to_vertex_handle(fan[half]).idx());
  e.faces.push_back({vi, wh, copy});
  e.faces.push_back({copy, w0, vi});
  // A copy along the edge to w0: that needle lies on it; the other is 2e-12 x sin(angle between the
  // edges to w0 and wh) thin, of zero area where they are nearly opposite (sin < about 1/2).
  for (const std::uint32_t w : {wh, w0}) e.zero_area += test::zero_area(e.points[vi], e.points[w], e.points[copy]);
}

/// Puts `n` points on the edge of h (b -> a), splits h's face (b, a, y) at them and fills the
/// flat polygon (b, a, points...) between the points and the edge with n caps, whose longest edge
/// a-b is the edge of the face across h, or the boundary.
void add_caps(const TriMesh& mesh, TriMesh::HalfedgeHandle h, int n, Edited& e) {
  const auto b = static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx());
  const auto a = static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx());
  const auto y = static_cast<std::uint32_t>(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)).idx());
  std::vector<std::uint32_t> q{a};
  for (int i = 1; i <= n; ++i) {
    q.push_back(static_cast<std::uint32_t>(e.points.size()));
    e.points.push_back(e.points[a] + (e.points[b] - e.points[a]) * (double(i) / (n + 1)));
  }
  q.push_back(b);
  e.faces[mesh.face_handle(h).idx()] = {q[1], q[0], y};
  for (int i = 1; i <= n; ++i) e.faces.push_back({q[i + 1], q[i], y});
  for (int i = 0; i < n; ++i) e.faces.push_back({b, q[i], q[i + 1]});
  e.zero_area += n;
}

struct Topology {
  long euler;
  std::size_t boundary_loops, components;
  bool operator==(const Topology&) const = default;
};
std::ostream& operator<<(std::ostream& os, const Topology& t) {
  return os << "{euler " << t.euler << ", boundary loops " << t.boundary_loops << ", components " << t.components
            << "}";
}
Topology topology(const TriMesh& m) {
  return {test::euler_characteristic(m), test::count_boundary_loops(m), test::count_components(m)};
}

/// Reads the edited mesh; checks it valid, with the original's topology and no zero-area face,
/// and every added zero-area face repaired.
void check_repaired(const TriMesh& original, const Edited& e) {
  const std::string obj = write_mesh(test::make_soup(e.points, e.faces), Format::Obj);
  LoadedMesh m = read(obj);
  CHECK(topology(m.mesh) == topology(original));
  CHECK(test::check_loaded(m.mesh).empty());
  CHECK(test::check_mesh_valid(m.mesh, 1e-6).empty());  // no face below 1e-6 of the mean area, none folded
  const Repair* r = find_repair(m, "degenerate_faces_repaired");
  REQUIRE(r);
  CHECK(r->count == e.zero_area);
  CHECK(find_repair(m, "degenerate_faces_removed") == nullptr);
  std::size_t faces = 0;
  for (auto f : m.mesh.all_faces()) faces += m.mesh.status(f).deleted() ? 0 : 1;
  CHECK(faces == m.mesh.n_faces());  // garbage collected
}

std::vector<std::pair<std::string, TriMesh>> meshes_to_edit() {
  return {{"icosphere", test::make_icosphere(2)},
          {"torus", test::make_torus(24, 12, 1.0, 0.4)},
          {"double torus", test::make_double_torus(1.0, 2)},
          {"open grid", test::make_open_grid(12, 12, 1.0)}};
}

}  // namespace

TEST_CASE("Needles between near-coincident vertex copies are collapsed and the surface stays closed") {
  for (const auto& [name, mesh] : meshes_to_edit()) {
    INFO(name);
    Edited e = faces_of(mesh);
    const auto chosen = spread_vertices(mesh, /*interior=*/true, 6);
    REQUIRE(chosen.size() == 6);
    for (std::size_t i = 0; i < chosen.size(); ++i)
      add_needles(mesh, chosen[i], std::array{Offset::None, Offset::Relative, Offset::AlongEdge}[i % 3], e);
    check_repaired(mesh, e);
    // Each copy went back into its vertex: the vertices are the original ones.
    const std::string obj = write_mesh(test::make_soup(e.points, e.faces), Format::Obj);
    CHECK(read(obj).mesh.n_vertices() == mesh.n_vertices());
  }
}

TEST_CASE("Caps over points on an edge are flipped away and a closed surface stays closed") {
  for (const auto& [name, mesh] : meshes_to_edit()) {
    INFO(name);
    Edited e = faces_of(mesh);
    int n = 1;
    for (auto v : spread_vertices(mesh, /*interior=*/true, 4)) {
      // An interior edge: its halfedge out of v, whose face is split.
      add_caps(mesh, *mesh.voh_range(v).begin(), n, e);
      n = n % 3 + 1;  // 1, 2 or 3 collinear points on the edge
    }
    check_repaired(mesh, e);
  }
}

TEST_CASE("Caps on the boundary are removed and the boundary loops stay") {
  const TriMesh mesh = test::make_open_grid(8, 8, 1.0);
  Edited e = faces_of(mesh);
  int n = 1;
  for (auto v : spread_vertices(mesh, /*interior=*/false, 40)) {
    if (!mesh.is_boundary(v)) continue;
    for (auto h : mesh.voh_range(v))
      if (mesh.is_boundary(mesh.opposite_halfedge_handle(h)) && !mesh.is_boundary(h)) {
        add_caps(mesh, h, n, e);  // the face along the boundary split, caps between it and the boundary
        n = n % 3 + 1;
        break;
      }
  }
  REQUIRE(e.zero_area >= 6);
  check_repaired(mesh, e);
  CHECK(test::count_boundary_loops(mesh) == 1);
}

TEST_CASE("A needle's collapse never turns a small face beside it over") {
  // A needle 1000 long whose short edge (5e-4) has faces 1e-4 across beside it: collapsing the
  // edge one way turned face (1, 5, 6) over (signed area -2.5e-8 beside positive neighbours).
  const std::string obj =
      "v 0 0 0\nv 1000 0 0\nv 5e-4 0 0\nv 500 500 0\nv 3e-4 -1e-4 0\nv 3.5e-4 -2e-4 0\nv 7e-4 -1e-4 0\n"
      "f 1 2 4\nf 2 1 3\nf 3 1 5\nf 3 5 6\nf 3 6 7\nf 3 7 2\n";
  const LoadedMesh loaded = read(obj);
  const TriMesh& mesh = loaded.mesh;
  REQUIRE(mesh.n_faces() >= 3);
  for (auto f : mesh.faces()) {
    Vec3 p[3];
    int k = 0;
    for (auto v : mesh.fv_range(f)) p[k++] = mesh.point(v);
    const double z = ((p[1] - p[0]) % (p[2] - p[0]))[2];  // the mesh lies in z = 0, all faces up
    CHECK(z > 0);
  }
}
