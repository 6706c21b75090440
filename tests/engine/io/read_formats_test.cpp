// Reading each input format, with the format-specific details the readers must handle.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <vector>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "io_test_util.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

LoadedMesh read_as(const std::string& bytes, std::optional<Format> f = std::nullopt) {
  ReadOptions o;
  o.format = f;
  return read_mesh(bytes, o);
}

const std::string kCubeObj =
    "# a unit cube with quads\r\n"
    "mtllib cube.mtl\r\n"
    "o cube\r\n"
    "v 0 0 0\r\nv 1 0 0\r\nv 1 1 0\r\nv 0 1 0\r\n"
    "v 0 0 1\r\nv 1 0 1\r\nv 1 1 1\r\nv 0 1 1\r\n"
    "vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvn 0 0 1\r\n"
    "g bottom\r\ns off\r\nusemtl red\r\n"
    "f 1/1 4/2 3/3 2/1\r\n"
    "g top\r\ns 1\r\n"
    "f 5//1 6//1 7//1 8//1\r\n"
    "f 1/1/1 2/2/1 6/3/1 5/1/1\r\n"
    "f -7 -6 -2 -3\r\n"  // 2 3 7 6 through negative indices
    "f 3 4 8 7\r\n"
    "f 4 1 5 8\r\n";

/// A cube with a distinct value for each coordinate, as OFF: `header` (keyword and counts), then
/// its vertex and face records, the values of each joined by the separators given (vsep[k] after value k of a
/// vertex, fsep[k] after value k of a face: its vertex count, then indices) and ended by `end`.
std::string cube_off(const std::string& header, const std::array<std::string, 2>& vsep,
                     const std::array<std::string, 4>& fsep, const std::string& end = "\n") {
  static const char* const xs[2] = {"-1", "2.5"};
  static const char* const ys[2] = {"-1.25", "3"};
  static const char* const zs[2] = {"0.5", "4.75"};
  static const int corners[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  static const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                                  {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  std::string out = header;
  for (const auto& c : corners)
    out += std::string(xs[c[0]]) + vsep[0] + ys[c[1]] + vsep[1] + zs[c[2]] + end;
  for (const auto& q : quads)
    out += "4" + fsep[0] + std::to_string(q[0]) + fsep[1] + std::to_string(q[1]) + fsep[2] +
           std::to_string(q[2]) + fsep[3] + std::to_string(q[3]) + end;
  return out;
}

const std::string kCubeOff = cube_off("OFF\n8 6 12\n", {" ", " "}, {" ", " ", " ", " "});

/// The message of the MeshError that reading `bytes` throws ("" if it reads).
std::string read_error(const std::string& bytes) {
  try {
    read_as(bytes);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

/// The unit square's four corners (0,0,0) (1,0,0) (0,1,0) (1,1,0) as float32, base64 (48 bytes -> 64
/// characters): a glTF buffer for a strip or a fan.
std::string unit_square_base64() {
  std::string bin;
  auto put_f = [&](float v) { bin.append(reinterpret_cast<const char*>(&v), 4); };
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 1.f, 1.f, 0.f}) put_f(v);
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < bin.size(); i += 3) {
    unsigned v = (unsigned char)bin[i] << 16 | (unsigned char)bin[i + 1] << 8 | (unsigned char)bin[i + 2];
    b64 += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
  }
  return b64;
}

}  // namespace

TEST_CASE("OBJ: index forms, negative indices, groups, CRLF and quads") {
  LoadedMesh m = read_as(kCubeObj);
  CHECK(m.format == Format::Obj);
  CHECK(m.mesh.n_vertices() == 8);
  CHECK(m.mesh.n_faces() == 12);
  REQUIRE(!m.repairs.empty());
  CHECK(m.repairs[0].kind == "polygons_triangulated");
  CHECK(m.repairs[0].count == 6);
  MeshSummary s = summarize(m.mesh);
  CHECK(s.euler == 2);
  CHECK(s.boundary_loops == 0);
  CHECK(s.area == Approx(6.0));
  CHECK(test::check_loaded(m.mesh).empty());
}

TEST_CASE("OBJ: a comment from '#' may end any line, a face's too") {
  // Every line of the cube with a comment, after blanks or right after its last value.
  std::string commented;
  std::size_t n = 0;
  for (std::size_t at = 0, end; (end = kCubeObj.find("\r\n", at)) != std::string::npos; at = end + 2)
    commented += kCubeObj.substr(at, end - at) + (++n % 2 ? "   # c 1 2\r\n" : "#c\r\n");
  REQUIRE(n == 26);
  test::check_same_mesh(read_as(commented), read_as(kCubeObj));
  const std::string tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2 # c\nf 1 2 4\t#\nf 2 3 4#4\nf 1 4 3 #\n";
  CHECK(read_as(tetra).mesh.n_faces() == 4);
}

TEST_CASE("OBJ: a concave polygon is ear-clipped, not fanned across the outside") {
  // An L-shaped hexagon: a fan from vertex 0 would create a triangle outside the polygon.
  const std::string obj =
      "v 1 1 0\nv 2 1 0\nv 2 2 0\nv 0 2 0\nv 0 0 0\nv 1 0 0\n"
      "f 1 2 3 4 5 6\n";
  LoadedMesh m = read_as(obj);
  CHECK(m.mesh.n_faces() == 4);
  CHECK(summarize(m.mesh).area == Approx(3.0));
  for (auto f : m.mesh.faces()) CHECK(m.mesh.normal(f)[2] > 0.99);
}

TEST_CASE("OBJ: polygons of thousands of corners are ear-clipped too, star-shaped, notched or concave") {
  // Flat polygons in z = 0, counter-clockwise: a star whose radii alternate (every other corner
  // reflex; a fan from the first corner crosses the outside), and a disk with a deep notch cut into
  // it. Their triangles must cover the polygon once: n - 2 of them, all facing up, their areas adding
  // up to the polygon's.
  const double pi = std::acos(-1.0);
  auto polygon = [&](std::size_t n, auto radius_at) {
    std::vector<std::array<double, 2>> p(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double t = 2 * pi * double(i) / double(n), r = radius_at(i, t);
      p[i] = {r * std::cos(t), r * std::sin(t)};
    }
    return p;
  };
  // A triangle whose sides bow inward: every corner but its three tips reflex, so that each ear's
  // test meets thousands of reflex corners unless it looks only near the ear.
  auto concave_triangle = [&](std::size_t per_side) {
    std::vector<std::array<double, 2>> p;
    for (int k = 0; k < 3; ++k) {
      const double ta = pi / 2 + 2 * pi * k / 3, tb = ta + 2 * pi / 3;
      for (std::size_t i = 0; i < per_side; ++i) {
        const double t = double(i) / double(per_side), bow = 1 - 0.2 * std::sin(pi * t);
        const double x = (1 - t) * std::cos(ta) + t * std::cos(tb), y = (1 - t) * std::sin(ta) + t * std::sin(tb);
        p.push_back({bow * x, bow * y});
      }
    }
    return p;
  };
  const std::pair<const char*, std::vector<std::array<double, 2>>> cases[] = {
      {"star 2400", polygon(2400, [](std::size_t i, double) { return i % 2 ? 0.8 : 1.0; })},
      {"star 301", polygon(301, [](std::size_t i, double) { return i % 2 ? 0.5 : 1.0; })},
      {"notched disk 5000", polygon(5000, [&](std::size_t, double t) { return std::abs(t - pi) < 0.3 ? 0.05 : 1.0; })},
      {"concave triangle 30000", concave_triangle(10000)},
  };
  for (const auto& [what, p] : cases) {
    CAPTURE(what);
    std::string obj;
    double area = 0;  // shoelace
    for (std::size_t i = 0; i < p.size(); ++i) {
      obj += "v ";
      obj += std::to_string(p[i][0]);
      obj += ' ';
      obj += std::to_string(p[i][1]);
      obj += " 0\n";
      const auto& q = p[(i + 1) % p.size()];
      area += 0.5 * (p[i][0] * q[1] - q[0] * p[i][1]);
    }
    obj += "f";
    for (std::size_t i = 1; i <= p.size(); ++i) {
      obj += ' ';
      obj += std::to_string(i);
    }
    obj += "\n";
    const LoadedMesh m = read_as(obj);
    CHECK(m.mesh.n_faces() == p.size() - 2);
    double sum = 0;
    std::size_t down = 0;
    for (auto f : m.mesh.faces()) {
      sum += m.mesh.calc_face_area(f);
      if (!(m.mesh.normal(f)[2] > 0.99)) ++down;
    }
    CHECK(down == 0);
    CHECK(sum == Approx(area).epsilon(1e-4));
  }
}

TEST_CASE("OFF: ASCII with comments, colours and counts on the header line, binary OFF") {
  const std::string off =
      "COFF 4 4 6 # tetrahedron\n"
      "# vertices\n"
      "0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n\n0 0 1 9 9 9 255\n"
      "3 0 2 1 1 0 0\n3 0 1 3\n3 1 2 3\n3 0 3 2\n";
  LoadedMesh m = read_as(off);
  CHECK(m.format == Format::Off);
  CHECK(m.mesh.n_faces() == 4);
  CHECK(summarize(m.mesh).euler == 2);

  PolygonSoup soup = to_soup(test::make_icosphere(1));
  LoadedMesh b = read_as(test::write_off_binary(soup));
  CHECK(b.format == Format::Off);
  CHECK(b.mesh.n_faces() == 80);
  CHECK(b.repairs.empty());
}

TEST_CASE("OFF: content after the declared faces is reported as ignored, a negative binary face size named") {
  const LoadedMesh plain = read_as(kCubeOff);
  // Two more faces than the header's 6, a comment and a blank line among them: the 12 are read,
  // the rest is said (it was dropped silently, holes and all).
  const LoadedMesh m = read_as(kCubeOff + "# two more\n3 0 1 2\n\n3 4 5 6 0.5\n");
  test::check_same_mesh(m, plain);
  // The cube's quads are triangulated (one repair); the lines after its faces are the other.
  REQUIRE(m.repairs.size() == plain.repairs.size() + 1);
  const Repair& ignored = m.repairs.front();
  CHECK(ignored.kind == "off_lines_after_faces_ignored");
  CHECK(ignored.count == 2);
  const std::size_t cube_lines = static_cast<std::size_t>(std::count(kCubeOff.begin(), kCubeOff.end(), '\n'));
  CHECK(ignored.detail == "2 content lines after the 6 faces the header declares ignored, from line " +
                              std::to_string(cube_lines + 2) + " (is the header's face count too small?)");
  // Comments and blank lines alone after the faces are nothing to report, nor NUL padding or a DOS
  // end-of-file mark.
  CHECK(read_as(kCubeOff + "# end\n\n  \n").repairs.size() == plain.repairs.size());
  CHECK(read_as(kCubeOff + std::string("\0\0\0\n\x1a", 5)).repairs.size() == plain.repairs.size());

  // Binary: a face whose vertex count is negative is named as such (it said the file ended first).
  std::string bin = test::write_off_binary(to_soup(test::make_icosphere(0)));
  const std::size_t face0 = std::string("OFF BINARY\n").size() + 12 + 12 * 12;  // header, counts, 12 points
  const unsigned char minus_three[4] = {0xff, 0xff, 0xff, 0xfd};  // big-endian int32 -3
  bin.replace(face0, 4, reinterpret_cast<const char*>(minus_three), 4);
  CHECK(read_error(bin) == "binary OFF: face 0 has a negative vertex count -3");
}

TEST_CASE("OFF: records wrapped over lines read as the one-record-per-line file") {
  const LoadedMesh plain = read_as(kCubeOff);
  REQUIRE(plain.mesh.n_vertices() == 8);
  REQUIRE(plain.mesh.n_faces() == 12);
  CHECK(plain.mesh.point(plain.mesh.vertex_handle(6)) == Vec3(2.5, 3, 4.75));
  const std::array<std::string, 2> v1 = {" ", " "};
  const std::array<std::string, 4> f1 = {" ", " ", " ", " "};
  const std::pair<const char*, std::string> variants[] = {
      {"faces wrapped after each index", cube_off("OFF\n8 6 12\n", v1, {"\n", "\n", "\n", "\n"})},
      {"faces wrapped, comments and blank lines between the pieces",
       cube_off("OFF\n8 6 12\n", v1, {" # count\n", "\n\n", " # 2nd\n# comment\n", "\t\r\n  \n"})},
      {"vertices split after x", cube_off("OFF\n8 6 12\n", {"\n", " "}, f1)},
      {"vertices split after y, comments between", cube_off("OFF\n8 6 12\n", {" ", " # z next\n\n"}, f1)},
      {"vertices one value a line, CRLF", cube_off("OFF\r\n8 6 12\r\n", {"\r\n", "\r\n"}, f1, "\r\n")},
      {"counts split", cube_off("OFF\n8\n6 0\n", v1, f1)},
      {"counts after the keyword, split", cube_off("OFF 8\n6 12\n", v1, f1)},
      {"counts one a line, comments between", cube_off("OFF\n8\n# faces\n\n6 # then edges\n12\n", v1, f1)},
      {"edge count on its own line", cube_off("OFF 8 6\n12\n", v1, f1)},
      // The first value, -1, alone on the line after the counts: a vertex's, since the next line
      // does not hold a whole vertex.
      {"vertices one value a line, no edge count", cube_off("OFF\n8 6\n", {"\n", "\n"}, f1)},
      {"all wrapped", cube_off("OFF # cube\n8\n\n6\n12 # edges\n", {"\n# y\n", "\n"},
                               {"\n", " ", "\n\n", "\n# last\n"})},
  };
  for (const auto& [what, text] : variants) {
    CAPTURE(what, text);
    LoadedMesh wrapped;
    REQUIRE_NOTHROW(wrapped = read_as(text));
    CHECK(wrapped.format == Format::Off);
    test::check_same_mesh(wrapped, plain);
  }
}

TEST_CASE("OFF: extra values after a wrapped record's last value stay ignored") {
  const LoadedMesh plain = read_as(kCubeOff);
  // COFF colours after the 3rd coordinate, a face colour after the last index, on the line where
  // the record completes.
  const std::string coff = cube_off("COFF\n8 6 12\n", {"\n", " "}, {" ", "\n", " ", "\n"}, " 0.5 0.25 1 1\n");
  test::check_same_mesh(read_as(coff), plain);
  // NOFF normals on the completing line.
  const std::string noff = cube_off("NOFF\n8 6 12\n", {" ", "\n"}, {"\n", " ", " ", " "}, " 0 0 1\n");
  test::check_same_mesh(read_as(noff), plain);
}

TEST_CASE("OFF: files read before wrapping was accepted read the same") {
  const LoadedMesh plain = read_as(kCubeOff);
  // Colours and normals after the coordinates, face colours after the indices, counts on the
  // keyword line, no edge count: the extra values are not taken as the next record.
  const std::array<std::string, 2> v1 = {" ", " "};
  const std::array<std::string, 4> f1 = {" ", " ", " ", " "};
  const std::pair<const char*, std::string> variants[] = {
      {"COFF with vertex and face colours", cube_off("COFF\n8 6 12\n", v1, f1, " 255 0 0 255\n")},
      {"NOFF", cube_off("NOFF\n8 6 12\n", v1, f1, " 0 0 1\n")},
      {"counts on the keyword line", cube_off("OFF 8 6 12 # cube\n", v1, f1)},
      {"no edge count", cube_off("OFF\n8 6\n", v1, f1)},
      {"no edge count, after the keyword", cube_off("OFF 8 6\n", v1, f1)},
  };
  for (const auto& [what, text] : variants) {
    CAPTURE(what, text);
    LoadedMesh m;
    REQUIRE_NOTHROW(m = read_as(text));
    test::check_same_mesh(m, plain);
  }
  // The tetrahedron with a face colour of one value on a face of three: 4 faces, not a 4-gon.
  const LoadedMesh t = read_as("OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1 7\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  CHECK(t.mesh.n_faces() == 4);
  CHECK(t.repairs.empty());
}

TEST_CASE("OFF: wrapped records cut short or with a bad value are refused, naming the line and the problem") {
  using Catch::Contains;
  // (The comment leaves the bytes that the header's size check wants: 5 a vertex, 7 a face.)
  const std::string tri = "OFF\n3 1 0\n0 0 0 # a triangle, its last vertex and face wrapped or cut\n1 0 0\n";
  CHECK_NOTHROW(read_as(tri + "0\n1 0\n3 0\n1\n2\n"));
  CHECK(read_error(tri + "0 1\n") == "OFF line 5: vertex 2 has fewer than 3 coordinates (the file ends after 2)");
  CHECK(read_error(tri + "0\n# 1 0\n\n") == "OFF line 5: vertex 2 has fewer than 3 coordinates (the file ends after 1)");
  CHECK(read_error(tri + "0 1 0\n3 0\n# 1\n1\n") ==
        "OFF line 6: face 0 declares 3 vertices but the file ends after 2");
  CHECK(read_error(tri + "0 1 0\n3\n") == "OFF line 6: face 0 declares 3 vertices but the file ends after 0");
  CHECK(read_error(tri) == "OFF: file ends after 2 of 3 vertices");
  CHECK(read_error(tri + "0 1 0\n") == "OFF: file ends after 0 of 1 faces");
  CHECK(read_error("OFF\n") == "OFF: missing the vertex/face count line");
  CHECK(read_error("OFF\n3 # faces next\n\n") == "OFF line 2: missing face count");
  // A bad value in a continuation: its own line.
  CHECK_THAT(read_error(tri + "0\n1 x\n3 0 1 2\n"), Contains("OFF line 6") && Contains("bad coordinate 'x' of vertex 2"));
  CHECK_THAT(read_error(tri + "0 1 0\n3 0\n1 y\n"), Contains("OFF line 7") && Contains("bad vertex index 'y' in face 0"));
  CHECK_THAT(read_error("OFF\n3\nz 0\n"), Contains("OFF line 3") && Contains("bad face count 'z'"));
  // A value missing inside the file: the vertex takes the next line's first value, and the file
  // ends early, with the record that was continued named.
  CHECK(read_error("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n") ==
        "OFF: file ends after 0 of 1 faces (vertex 1 at line 4 is the first record continued on the next line)");
  // A face declaring more indices than it lists, at the end: as before.
  CHECK_THAT(read_error(tri + "0 1 0\n4 0 1 2\n"), Contains("OFF line 6") && Contains("declares 4"));

  // The wrapped cube cut after each of its lines: refused, saying the file ends or is short.
  const std::string wrapped = cube_off("OFF 8\n6\n12\n", {"\n", "\n"}, {"\n", " # i\n", "\n\n", "\n"});
  REQUIRE_NOTHROW(read_as(wrapped));
  std::size_t cuts = 0;
  for (std::size_t at = wrapped.find('\n'); at + 1 < wrapped.size(); at = wrapped.find('\n', at + 1)) {
    const std::string message = read_error(wrapped.substr(0, at + 1));
    CAPTURE(at, message);
    CHECK((message.find("ends after") != std::string::npos || message.find("missing") != std::string::npos ||
           message.find("header claims") != std::string::npos));
    ++cuts;
  }
  CHECK(cuts > 60);
}

TEST_CASE("PLY: ascii, both binary byte orders, extra properties and elements") {
  PolygonSoup soup = to_soup(test::make_icosphere(1));
  for (const std::string& bytes : {test::write_ply_ascii(soup), test::write_ply_big_endian(soup),
                                   write_mesh(soup, Format::Ply)}) {
    LoadedMesh m = read_as(bytes);
    CHECK(m.format == Format::Ply);
    CHECK(m.mesh.n_vertices() == soup.points.size());
    CHECK(m.mesh.n_faces() == 80);
    CHECK(m.repairs.empty());
    CHECK(m.mesh.point(TriMesh::VertexHandle(5))[0] == Approx(soup.points[5][0]).epsilon(1e-6));
  }
}

TEST_CASE("STL: ASCII, binary, and binary whose header starts with 'solid'") {
  PolygonSoup soup = to_soup(test::make_icosphere(1));
  LoadedMesh a = read_as(test::write_stl_ascii(soup));
  CHECK(a.format == Format::Stl);
  CHECK(a.mesh.n_vertices() == 42);  // welded by position, not reported as a repair
  CHECK(a.repairs.empty());
  // Keywords in upper case, as some exporters write them (read as a binary file of 1.3 billion
  // triangles), with the format told and found from the content.
  std::string upper = test::write_stl_ascii(soup);
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  CHECK(detect_format(upper) == Format::Stl);
  for (const std::optional<Format> f : {std::optional<Format>(Format::Stl), std::optional<Format>()}) {
    const LoadedMesh u = read_as(upper, f);
    CHECK(u.mesh.n_vertices() == 42);
    CHECK(u.mesh.n_faces() == 80);
  }

  std::string bin = write_mesh(soup, Format::Stl);
  bin.replace(0, 12, "solid trick ");
  CHECK(detect_format(bin) == Format::Stl);
  LoadedMesh b = read_as(bin);
  CHECK(b.mesh.n_vertices() == 42);
  CHECK(b.mesh.n_faces() == 80);
  CHECK(b.repairs.empty());
}

TEST_CASE("glTF: data URI buffer and GLB") {
  PolygonSoup soup = to_soup(test::make_icosphere(1));
  LoadedMesh g = read_as(test::write_gltf_data_uri(soup));
  CHECK(g.format == Format::Gltf);
  CHECK(g.mesh.n_faces() == 80);
  LoadedMesh b = read_as(write_mesh(soup, Format::Glb));
  CHECK(b.format == Format::Glb);
  CHECK(b.mesh.n_faces() == 80);
}

TEST_CASE("glTF: node transforms (TRS and matrix, nested), strips, fans and several meshes are merged") {
  // One triangle-strip quad in mesh 0 (used twice: translated and mirrored by a matrix) and a fan in mesh 1.
  const std::string b64 = unit_square_base64();
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,2]}],
    "nodes":[{"translation":[0,0,5],"children":[1],"mesh":0},
             {"matrix":[-1,0,0,0, 0,1,0,0, 0,0,1,0, 10,0,0,1],"mesh":0},
             {"scale":[2,2,2],"rotation":[0,0,0.7071068,0.7071068],"mesh":1}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5}]},
              {"primitives":[{"attributes":{"POSITION":0},"mode":6},{"attributes":{"POSITION":0},"mode":1}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}],
    "bufferViews":[{"buffer":0,"byteLength":48}],
    "buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,)" + b64 + R"("}]})";
  LoadedMesh m = read_as(gltf);
  CHECK(m.mesh.n_faces() == 6);  // 2 + 2 (strip, twice) + 2 (fan); the LINES primitive adds none
  MeshSummary s = summarize(m.mesh);
  CHECK(s.components == 3);
  CHECK(s.area == Approx(1 + 1 + 4 * 0.5 + 4 * 0.5));  // fan 0,1,2 / 0,2,3 of the unit square scaled by 2
  // The mirrored copy sits at x in [9, 10], z = 5, and still faces +z (winding flipped with the mirror).
  bool found_mirror = false;
  for (auto f : m.mesh.faces()) {
    Vec3 c = m.mesh.calc_face_centroid(f);
    if (c[0] > 9 && c[0] < 10) {
      found_mirror = true;
      CHECK(c[2] == Approx(5));
    }
  }
  CHECK(found_mirror);
  CHECK(s.bbox_min[0] == Approx(-2));  // the rotated fan reaches x = -2
  CHECK(s.bbox_max[2] == Approx(5));
}

TEST_CASE("glTF: a node transform past the range of double is named, not reported as a soup vertex") {
  // The unit square's strip under a node with a given transform, below a parent scaled by 1e200.
  auto scene = [](const std::string& child) {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
      "nodes":[{"scale":[1e200,1e200,1e200],"children":[1]},)" + child + R"(],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5}]}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}],
      "bufferViews":[{"buffer":0,"byteLength":48}],
      "buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,)" + unit_square_base64() + R"("}]})";
  };
  // Scaled by 1e200 again: the product overflows (and 0 * inf is NaN); before, "vertex 0 has a
  // non-finite coordinate (nan, ...)".
  CHECK(read_error(scene(R"({"scale":[1e200,1e200,1e200],"mesh":0})")) ==
        "glTF: node 1's transform (its matrix, translation, rotation or scale, times its parents') is not finite");
  // A finite transform (1e308 along x, moved 1e308) that a finite point overflows through: the
  // element and its stored value named.
  CHECK(read_error(scene(R"({"translation":[1e108,0,0],"scale":[1e108,1,1],"mesh":0})")) ==
        "glTF: mesh 0 primitive 0 POSITION element 1 (1, 0, 0) is past the range of double once its node's "
        "transform is applied");
  // Large but finite: read.
  CHECK(read_error(scene(R"({"scale":[1e-100,1e-100,1e-100],"mesh":0})")).empty());
  // The same overflowing transform over a mesh of lines only places no surface point: read, with
  // the strip of another node (it was refused by the first form of the check).
  const std::string lines_only = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,2]}],
    "nodes":[{"scale":[1e200,1e200,1e200],"children":[1]},{"scale":[1e200,1e200,1e200],"mesh":1},{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5}]},{"primitives":[{"attributes":{"POSITION":0},"mode":1}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}],
    "bufferViews":[{"buffer":0,"byteLength":48}],
    "buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,)" + unit_square_base64() + R"("}]})";
  CHECK(read_error(lines_only).empty());
  CHECK(read_as(lines_only).mesh.n_faces() == 2);
}

TEST_CASE("glTF: a buffer pointing to an external file is refused without reading it") {
  PolygonSoup soup = to_soup(test::make_icosphere(0));
  for (const std::string uri : {"../../../etc/passwd", "mesh.bin", "/etc/hostname"}) {
    try {
      read_as(test::write_gltf_data_uri(soup, uri));
      FAIL("external URI accepted: " << uri);
    } catch (const MeshError& e) {
      CHECK_THAT(e.what(), Catch::Contains("external file") && Catch::Contains(uri));
    }
  }
}

TEST_CASE("glTF and GLB errors a service QA found unclear say what is wrong") {
  const std::string glb = write_mesh(to_soup(test::make_icosphere(1)), Format::Glb);
  // Cut short: tinygltf said "Invalid glTF binary."
  CHECK_THAT(read_error(glb.substr(0, glb.size() - 100)),
             Catch::Contains("GLB: the file is " + std::to_string(glb.size() - 100) + " bytes, but its header says " +
                             std::to_string(glb.size())));
  CHECK_THAT(read_error(glb.substr(0, 40)), Catch::Contains("GLB:") && Catch::Contains("cut short"));
  // A JSON syntax error without the JSON library's tag ("[json.exception.parse_error.101]").
  const std::string bad_json = read_error(R"({"asset":{"version":"2.0"},)");
  CHECK_THAT(bad_json, Catch::StartsWith("glTF: "));
  CHECK(bad_json.find("json.exception") == std::string::npos);
  // A buffer's data: URI that tinygltf does not decode was "an external file 'data:...'".
  PolygonSoup soup = to_soup(test::make_icosphere(0));
  for (const char* uri : {"data:application/octet-stream,%00%01", "data:;base64,AAAA"})
    CHECK_THAT(read_error(test::write_gltf_data_uri(soup, uri)),
               Catch::Contains("a buffer's data: URI that this reader does not decode") &&
                   !Catch::Contains("external file"));
  // An image's (a texture file, a webp data: URI) is not needed for the surface: read (the file was
  // refused for its texture).
  const std::string mesh = test::write_gltf_data_uri(soup);
  REQUIRE(mesh.back() == '}');
  for (const char* image : {"texture.png", "data:image/webp;base64,AAAA"}) {
    CAPTURE(image);
    const std::string textured = mesh.substr(0, mesh.size() - 1) + R"(,"images":[{"uri":")" + image + R"("}]})";
    CHECK(read_error(textured).empty());
  }
  // Points only: "holds no vertices and no faces".
  const std::string points = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
    "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":0}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}],
    "bufferViews":[{"buffer":0,"byteLength":48}],
    "buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,)" + unit_square_base64() + R"("}]})";
  CHECK(read_error(points) == "glTF: its primitives are points (mode 0), no triangles: there is no surface to remesh");
  // A required extension that changes how the data reads (meshopt: compressed buffer views) was
  // passed over, the positions read as they lay; one about looks only is read past.
  auto requiring = [](const std::string& ext) {
    return R"({"asset":{"version":"2.0"},"extensionsUsed":[")" + ext + R"("],"extensionsRequired":[")" + ext +
           R"("],"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5}]}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"}],
      "bufferViews":[{"buffer":0,"byteLength":48}],
      "buffers":[{"byteLength":48,"uri":"data:application/octet-stream;base64,)" + unit_square_base64() + R"("}]})";
  };
  CHECK(read_error(requiring("EXT_meshopt_compression")) ==
        "glTF: its buffers are compressed (EXT_meshopt_compression), which this reader does not decode");
  CHECK_THAT(read_error(requiring("EXT_mesh_gpu_instancing")), Catch::Contains("instanced meshes"));
  // Required by exporters for what does not move the surface: read as before (three.js requires
  // KHR_mesh_quantization for 8- and 16-bit normals).
  for (const char* ext : {"KHR_materials_emissive_strength", "KHR_mesh_quantization", "KHR_texture_basisu"})
    CHECK(read_error(requiring(ext)).empty());
}

TEST_CASE("Format detection and names") {
  CHECK(parse_format("a/b/mesh.OBJ") == Format::Obj);
  CHECK(parse_format(".glb") == Format::Glb);
  CHECK(parse_format("ply") == Format::Ply);
  CHECK_FALSE(parse_format("mesh.docx").has_value());
  CHECK(detect_format("ply\nformat ascii 1.0\n") == Format::Ply);
  CHECK(detect_format("OFF\n3 1 0\n") == Format::Off);
  CHECK(detect_format("  {\"asset\":{}}") == Format::Gltf);
  CHECK(detect_format("# comment\nv 1 2 3\n") == Format::Obj);
  CHECK(detect_format("solid x\nfacet normal") == Format::Stl);
  CHECK_FALSE(detect_format("hello world").has_value());
  for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Gltf, Format::Glb, Format::Xyz}) {
    CHECK(parse_format(format_name(f)) == f);
    CHECK(!mime_type(f).empty());
  }
  CHECK(mime_type(Format::Glb) == "model/gltf-binary");
}

TEST_CASE("glTF and GLB given under each other's name are read by their content") {
  PolygonSoup soup = to_soup(test::make_icosphere(1));
  CHECK(read_as(write_mesh(soup, Format::Glb), Format::Gltf).format == Format::Glb);
  CHECK(read_as(test::write_gltf_data_uri(soup), Format::Glb).format == Format::Gltf);
}

TEST_CASE("glTF: JSON nested past the reader's depth is refused, not a stack overflow") {
  // 20 000 nested arrays in "extras" (40 KB) overflowed tinygltf's recursive parser; 100 are fine.
  const std::string mesh = test::write_gltf_data_uri(to_soup(test::make_icosphere(0)));
  REQUIRE(mesh.front() == '{');
  auto nested = [&](std::size_t depth) {
    return "{\"extras\":" + std::string(depth, '[') + std::string(depth, ']') + "," + mesh.substr(1);
  };
  CHECK(read_as(nested(100)).mesh.n_faces() == 20);
  for (std::size_t depth : {300, 20000}) {
    try {
      read_as(nested(depth));
      FAIL("nesting of " << depth << " accepted");
    } catch (const MeshError& e) {
      CHECK_THAT(e.what(), Catch::Contains("nests arrays and objects more than 256 levels"));
    }
  }
  // Brackets inside strings do not count.
  CHECK(read_as("{\"extras\":\"" + std::string(1000, '[') + "\"," + mesh.substr(1)).mesh.n_faces() == 20);
  // The same in a GLB's JSON chunk.
  std::string json = nested(20000);
  json.resize((json.size() + 3) / 4 * 4, ' ');
  std::string glb = "glTF";
  auto put32 = [&](std::uint32_t v) { glb.append(reinterpret_cast<const char*>(&v), 4); };
  put32(2);
  put32(static_cast<std::uint32_t>(20 + json.size()));
  put32(static_cast<std::uint32_t>(json.size()));
  glb += "JSON" + json;
  CHECK_THROWS_WITH(read_as(glb), Catch::Contains("nests arrays and objects"));
}

TEST_CASE("glTF: a scene that instances its meshes into billions of triangles is refused") {
  // 3 positions and 3000 byte indices (1000 triangles), under a chain of 16 nodes that each list the
  // next twice: 65 536 instances, 65 million triangles from a file of a few KB.
  std::string bin;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) bin.append(reinterpret_cast<const char*>(&v), 4);
  for (int i = 0; i < 3000; ++i) bin.push_back(static_cast<char>(i % 3));
  while (bin.size() % 3) bin.push_back('\0');
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string b64;
  for (std::size_t i = 0; i < bin.size(); i += 3) {
    unsigned v = (unsigned char)bin[i] << 16 | (unsigned char)bin[i + 1] << 8 | (unsigned char)bin[i + 2];
    b64 += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
  }
  std::string nodes;
  for (int n = 0; n < 16; ++n)
    nodes += "{\"children\":[" + std::to_string(n + 1) + "," + std::to_string(n + 1) + "]},";
  nodes += "{\"mesh\":0}";
  const std::string gltf = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[)" + nodes +
                           R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
                 {"bufferView":1,"componentType":5121,"count":3000,"type":"SCALAR"}],
    "bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":3000}],
    "buffers":[{"byteLength":)" + std::to_string(bin.size()) +
                           R"(,"uri":"data:application/octet-stream;base64,)" + b64 + R"("}]})";
  CHECK_THROWS_WITH(read_as(gltf), Catch::Contains("expands to more than") && Catch::Contains("triangles"));
}

TEST_CASE("glTF node hierarchies: a flat scene of many nodes reads, a cycle and shared subtrees are refused") {
  const std::string tri = R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
    "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],
    "bufferViews":[{"buffer":0,"byteLength":36}],
    "buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
  auto scene = [&](const std::string& roots, const std::string& nodes) {
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[)" + roots + R"(]}],"nodes":[)" + nodes + "]," + tri;
  };
  // 120 000 nodes side by side, each one triangle: read (it was refused as "not a tree").
  std::string roots, nodes;
  for (int n = 0; n < 120000; ++n) {
    if (n > 0) roots += ',', nodes += ',';
    roots += std::to_string(n);
    nodes += R"({"mesh":0,"translation":[)";
    nodes += std::to_string(2 * n);
    nodes += ",0,0]}";
  }
  CHECK(read_as(scene(roots, nodes)).mesh.n_faces() == 120000);
  // A node that is its own child.
  CHECK_THROWS_WITH(read_as(scene("0", R"({"mesh":0,"children":[0]})")), Catch::Contains("or has a cycle"));
  // 40 levels, each referencing the next twice: 2^40 visits of the last.
  std::string chain;
  for (int n = 0; n < 40; ++n) chain += "{\"children\":[" + std::to_string(n + 1) + "," + std::to_string(n + 1) + "]},";
  chain += R"({"mesh":0})";
  CHECK_THROWS_WITH(read_as(scene("0", chain)), Catch::Contains("visits its nodes more than"));
}

TEST_CASE("A file given under another format's name says what its content looks like") {
  const std::string ply = write_mesh(test::make_icosphere(0), Format::Ply);
  const std::string off = write_mesh(test::make_icosphere(0), Format::Off);
  CHECK_THROWS_WITH(read_as(ply, Format::Obj), Catch::Contains("read as obj") && Catch::Contains("looks like ply"));
  CHECK_THROWS_WITH(read_as(off, Format::Obj), Catch::Contains("looks like off"));
  // Read by its content, it is fine; an empty OBJ is still just empty.
  CHECK(read_as(ply).mesh.n_faces() == 20);
  CHECK_THROWS_WITH(read_as("# nothing\n", Format::Obj), Catch::Contains("holds no vertices and no faces"));
  // An image under a .obj name: binary data, said to be so (it was "no vertices and no faces").
  const std::string png("\x89PNG\r\n\x1a\n\0\0\0\rIHDR\0\0\0\x10\0\0\0\x10\x08\x06\0\0\0", 33);
  CHECK_THROWS_WITH(read_as(png, Format::Obj), Catch::Contains("its content is binary data, not OBJ text"));
  // Refused by another format's reader: its complaint, and what the content looks like (an OFF file
  // given as STL or GLB got the reader's complaint alone).
  for (Format given : {Format::Stl, Format::Glb, Format::Ply}) {
    CAPTURE(format_name(given));
    CHECK_THROWS_WITH(read_as(off, given), Catch::Contains("read as " + std::string(format_name(given))) &&
                                               Catch::Contains("its content looks like off"));
  }
}

TEST_CASE("GLB: accessor and bufferView offsets whose sums wrap round 2^64 are refused, not read") {
  // A tetrahedron's 4 positions and 12 short indices, then padding: the bounds of the POSITION
  // accessor are the test's. With an unchecked sum, an offset near 2^64 wrapped round to a small
  // number, passed the test and made the reader take bytes from before the buffer (a crash in the
  // daemon, or heap contents read as coordinates).
  auto glb = [](const std::string& view_offset, const std::string& stride, const std::string& offset,
                const std::string& count) {
    std::string bin;
    for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f})
      bin.append(reinterpret_cast<const char*>(&v), 4);
    for (std::uint16_t i : {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}) bin.append(reinterpret_cast<const char*>(&i), 2);
    bin.append(1000, '\0');
    while (bin.size() % 4) bin.push_back('\0');
    std::string json = R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "buffers":[{"byteLength":)" + std::to_string(bin.size()) + R"(}],
      "bufferViews":[{"buffer":0,"byteOffset":)" + view_offset + R"(,"byteLength":48)" +
                       (stride.empty() ? "" : ",\"byteStride\":" + stride) + R"(},
                     {"buffer":0,"byteOffset":48,"byteLength":24}],
      "accessors":[{"bufferView":0,"byteOffset":)" + offset + R"(,"componentType":5126,"count":)" + count +
                       R"(,"type":"VEC3"},
                   {"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}]})";
    while (json.size() % 4) json.push_back(' ');
    std::string out = "glTF";
    auto put32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
    put32(2);
    put32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    put32(static_cast<std::uint32_t>(json.size()));
    out += "JSON" + json;
    put32(static_cast<std::uint32_t>(bin.size()));
    out += std::string("BIN\0", 4) + bin;
    return out;
  };
  // The well-formed file reads.
  CHECK(read_as(glb("0", "", "0", "4")).mesh.n_faces() == 4);
  // 2^64 - 252 * 3 - 12: with stride 252 and 4 elements, start + 252 * 3 + 12 wraps to 0.
  CHECK_THROWS_WITH(read_as(glb("0", "252", "18446744073709550848", "4")),
                    Catch::Contains("accessor 0 reaches past the end of its bufferView"));
  // 2^64 - 48: the accessor would start 48 bytes before the buffer.
  CHECK_THROWS_WITH(read_as(glb("0", "", "18446744073709551568", "4")), Catch::Contains("reaches past the end"));
  // A bufferView offset that wraps its end round to a small number.
  CHECK_THROWS_WITH(read_as(glb("18446744073709551600", "", "0", "4")),
                    Catch::Contains("bufferView 0 reaches past the end of its buffer"));
  // One element too many, and an offset that leaves no room for one element.
  CHECK_THROWS_WITH(read_as(glb("0", "", "0", "5")), Catch::Contains("reaches past the end"));
  CHECK_THROWS_WITH(read_as(glb("0", "", "40", "1")), Catch::Contains("reaches past the end"));
}

TEST_CASE("GLB: a buffer of byteLength 0 is a malformed file, not an escaped std::out_of_range") {
  // tinygltf copies the BIN chunk to data.at(0) of the buffer, which throws on an empty one: the
  // CLI said "error: vector::_M_range_check" and exited 1 as for an internal error.
  const std::string json = R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 0}]}   )";
  REQUIRE(json.size() % 4 == 0);
  std::string out = "glTF";
  auto put32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  put32(2);
  put32(static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + 4));
  put32(static_cast<std::uint32_t>(json.size()));
  out += "JSON" + json;
  put32(4);
  out += std::string("BIN\0", 4) + std::string(4, '\0');
  CHECK_THROWS_AS(read_as(out), MeshError);
  CHECK_THROWS_WITH(read_as(out), Catch::StartsWith("GLB: malformed structure"));
}

TEST_CASE("A UTF-8 byte order mark before a text format is passed over: the same mesh as without it") {
  const std::string bom = "\xEF\xBB\xBF";
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const std::string off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  std::string stl = "solid tet\n";
  const char* facets[4][3] = {{"0 0 0", "0 1 0", "1 0 0"}, {"0 0 0", "1 0 0", "0 0 1"},
                              {"0 0 0", "0 0 1", "0 1 0"}, {"1 0 0", "0 1 0", "0 0 1"}};
  for (const auto& f : facets)
    stl += std::string("facet normal 0 0 0\nouter loop\nvertex ") + f[0] + "\nvertex " + f[1] + "\nvertex " + f[2] +
           "\nendloop\nendfacet\n";
  stl += "endsolid tet\n";
  for (const std::string& text : {obj, off, ply, stl}) {
    CAPTURE(text.substr(0, 12));
    const LoadedMesh plain = read_as(text);
    const LoadedMesh marked = read_as(bom + text);
    CHECK(plain.mesh.n_vertices() == 4);
    CHECK(plain.mesh.n_faces() == 4);
    CHECK(marked.format == plain.format);
    CHECK(marked.mesh.n_vertices() == plain.mesh.n_vertices());
    CHECK(marked.mesh.n_faces() == plain.mesh.n_faces());
    for (auto v : plain.mesh.vertices()) CHECK(marked.mesh.point(v) == plain.mesh.point(v));
    // Given its format by name too (the OBJ reader took the marked first line for an unknown one).
    CHECK(read_as(bom + text, plain.format).mesh.n_faces() == 4);
  }
}

TEST_CASE("Read errors name the file's real kind and print numbers short") {
  // A binary STL whose header starts with "solid" (many exporters write one), cut short: reported
  // as binary, with its sizes, not as an ASCII file without 'endsolid'.
  std::string stl = "solid exported by a binary writer";
  stl.resize(80, ' ');
  const std::uint32_t n = 12;
  stl.append(reinterpret_cast<const char*>(&n), 4);
  stl.append(50 * 5, '\0');
  CHECK_THROWS_WITH(read_as(stl), Catch::Contains("binary STL") && Catch::Contains("12 triangles"));
  // A PLY vertex index of 1e300: the message says 1e+300, not 301 digits.
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar double vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 1e300\n";
  try {
    read_as(ply);
    FAIL("read");
  } catch (const std::exception& e) {
    const std::string message = e.what();
    CAPTURE(message);
    CHECK(message.size() < 200);
    CHECK(message.find("1e+300") != std::string::npos);
  }
}
