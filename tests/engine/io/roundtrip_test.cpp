// Write then read back in every format: same connectivity, positions exact (or float32 for STL/GLB).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "io/mesh_io.h"
#include "io/summary.h"
#include "io/writers.h"
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

bool is_float_format(Format f) { return f == Format::Stl || f == Format::Glb || f == Format::Gltf; }

}  // namespace

TEST_CASE("Triangle meshes round-trip through every format") {
  std::vector<std::pair<std::string, TriMesh>> meshes;
  meshes.emplace_back("icosphere", test::make_icosphere(2, 1.7));
  meshes.emplace_back("torus", test::make_torus(12, 8, 2.0, 0.5));
  meshes.emplace_back("open grid", test::make_open_grid(5, 4, 0.3));
  for (auto& [name, mesh] : meshes) {
    for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Glb, Format::Gltf}) {
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

TEST_CASE("STL, GLB and glTF refuse coordinates float32 cannot hold, before writing anything") {
  // A tetrahedron 1e38 across with its apex at (0, 0, z); with `loose`, a point in no face there
  // (refused too: a mesh's vertices are all written, used or not).
  auto tetra = [](double z, double loose = 0) {
    std::vector<Vec3> points = {{0, 0, 0}, {1e38, 0, 0}, {0, 1e38, 0}, {0, 0, z}};
    if (loose != 0) points.emplace_back(0, 0, loose);
    return test::make_soup(points, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
  };
  const double largest = std::numeric_limits<float>::max();
  const double rounds_to_inf = largest + std::ldexp(1.0, 103);  // half float32's spacing there
  const auto dir =
      std::filesystem::temp_directory_path() / ("remesh_io_float32_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const auto& [f, name] : {std::pair{Format::Stl, "STL"}, {Format::Glb, "GLB"}, {Format::Gltf, "glTF"}}) {
    INFO(name);
    CHECK_THROWS_WITH(write_mesh(tetra(1e308), f),
                      std::string(name) + " cannot hold point 3 (0, 0, 1e+308): it stores coordinates as "
                                          "float32, at most about 3.4e38 in magnitude");
    CHECK_THROWS_WITH(write_mesh(tetra(1, -1e308), f),
                      Catch::StartsWith(std::string(name) + " cannot hold point 4 (0, 0, -1e+308)"));
    for (double z : {-1e39, rounds_to_inf, std::numeric_limits<double>::infinity()}) {
      CAPTURE(z);
      CHECK_THROWS_AS(write_mesh(tetra(z), f), std::range_error);
    }
    const std::string path = (dir / ("t." + std::string(format_name(f)))).string();
    CHECK_THROWS_AS(write_mesh_file(tetra(1e308), path), std::range_error);
    CHECK(!std::filesystem::exists(path));
    // Written as before: what rounds to float32's largest, as that.
    for (double z : {largest, std::nextafter(rounds_to_inf, 0.0)}) {
      CAPTURE(z);
      const LoadedMesh back = read_mesh(write_mesh(tetra(z), f));
      double top = 0;
      for (auto v : back.mesh.vertices()) top = std::max(top, back.mesh.point(v)[2]);
      CHECK(top == largest);
    }
  }
  // The double formats hold it.
  for (Format f : {Format::Obj, Format::Off})
    CHECK(write_mesh(tetra(1e308), f).find(" 1e+308\n") != std::string::npos);
  CHECK_NOTHROW(write_mesh(tetra(1e308), Format::Ply));
  std::filesystem::remove_all(dir);
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
  for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Glb, Format::Gltf}) {
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

TEST_CASE("Text glTF holds the GLB document, and its BIN chunk in base64") {
  auto u32 = [](const std::string& s, std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, s.data() + at, 4);
    return v;
  };
  const PolygonSoup polygons = test::make_soup({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}},
                                               {{0, 3, 2, 1}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}});
  for (const PolygonSoup& soup : {to_soup(test::make_icosphere(2, 1.7)), polygons}) {
    const std::string glb = write_mesh(soup, Format::Glb), gltf = write_mesh(soup, Format::Gltf);
    // GLB: header (12 bytes), JSON chunk (length, type, padded text), BIN chunk.
    const std::uint32_t json_length = u32(glb, 12);
    std::string json = glb.substr(20, json_length);
    while (!json.empty() && json.back() == ' ') json.pop_back();
    const std::size_t bin_at = 20 + json_length;
    REQUIRE(glb.substr(bin_at + 4, 4) == std::string("BIN\0", 4));
    std::string bin = glb.substr(bin_at + 8, u32(glb, bin_at));
    // The document states the unpadded length: the data URI holds that many bytes.
    const std::string length_key = R"("buffers":[{"byteLength":)";
    const std::size_t at = json.find(length_key);
    REQUIRE(at != std::string::npos);
    bin.resize(std::stoul(json.substr(at + length_key.size())));
    const std::string expected =
        json.substr(0, json.size() - 3) + R"(,"uri":"data:application/octet-stream;base64,)" + test::base64(bin) + "\"}]}\n";
    CHECK(gltf == expected);
  }
  // Points without faces (the dual of a single triangle: one atom): a POINTS primitive.
  const PolygonSoup atoms = test::make_soup({{0, 0, 0}, {1, 0, 0}, {0, 2, 0}}, {});
  for (Format f : {Format::Glb, Format::Gltf}) {
    const std::string bytes = write_mesh(atoms, f);
    CHECK(bytes.find(R"("primitives":[{"attributes":{"POSITION":0},"mode":0}])") != std::string::npos);
    CHECK(bytes.find(R"("count":3,"type":"VEC3")") != std::string::npos);
  }
  // An empty mesh: a document without buffers, as the GLB's, its scene without nodes.
  const PolygonSoup empty = test::make_soup({}, {});
  const std::string empty_glb = write_mesh(empty, Format::Glb);
  std::string empty_json = empty_glb.substr(20, u32(empty_glb, 12));
  while (!empty_json.empty() && empty_json.back() == ' ') empty_json.pop_back();
  CHECK(empty_json.find("buffers") == std::string::npos);
  CHECK(empty_json.find(R"("scenes":[{}])") != std::string::npos);  // an empty "nodes" is invalid glTF
  CHECK(write_mesh(empty, Format::Gltf) == empty_json + "\n");
}

TEST_CASE("GLB and glTF refuse what their 32-bit lengths cannot state") {
  // The guard write_glb and write_gltf call on their buffer and GLB's whole file (a mesh that big
  // needs more memory than a test has: the bound is checked here).
  constexpr std::size_t largest = 0xFFFFFFFFu;
  CHECK_NOTHROW(io::check_32bit_length(largest, "GLB"));
  CHECK_THROWS_AS(io::check_32bit_length(largest + 1, "GLB"), std::range_error);
  CHECK_THROWS_WITH(io::check_32bit_length(std::size_t{5} << 30, "glTF"),
                    "glTF cannot hold 5368709120 bytes of vertices and indices: its lengths are 32-bit, at most 4 GiB");
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

namespace {

/// A LAMMPS data file as read_data reads it (header counts and box, Masses, Atoms, Bonds), with
/// every rule that read_data enforces checked on the way.
struct LammpsData {
  std::size_t atoms = 0, bonds = 0, atom_types = 0, bond_types = 0;
  double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
  std::vector<Vec3> positions;                            ///< by atom id - 1
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  ///< bonded atom ids - 1, by bond id - 1
};

LammpsData parse_lammps(const std::string& text) {
  LammpsData d;
  std::istringstream in(text);
  std::string line, section;
  std::getline(in, line);  // the title line
  while (std::getline(in, line)) {
    if (line.find_first_not_of(' ') == std::string::npos) continue;
    std::istringstream l(line);
    if (line == "Masses" || line.rfind("Atoms", 0) == 0 || line == "Bonds") {
      section = line.substr(0, line.find(' '));
      // read_data: "Invalid data file section: Bonds" when the header counts none.
      if (section == "Bonds") CHECK(d.bonds > 0);
      continue;
    }
    if (section.empty()) {
      double a = 0, b = 0;
      std::string w1, w2;
      l >> a >> w1;
      if (w1 == "atoms") d.atoms = static_cast<std::size_t>(a);
      else if (w1 == "bonds") d.bonds = static_cast<std::size_t>(a);
      else if (w1 == "atom" && (l >> w2, w2 == "types")) d.atom_types = static_cast<std::size_t>(a);
      else if (w1 == "bond" && (l >> w2, w2 == "types")) d.bond_types = static_cast<std::size_t>(a);
      else {
        std::istringstream box(line);
        std::string lo_word, hi_word;
        box >> a >> b >> lo_word >> hi_word;
        const int k = lo_word == "xlo" ? 0 : lo_word == "ylo" ? 1 : lo_word == "zlo" ? 2 : -1;
        REQUIRE(k >= 0);
        d.lo[k] = a, d.hi[k] = b;
      }
    } else if (section == "Atoms") {
      std::size_t id = 0, molecule = 0, type = 0;
      Vec3 p;
      REQUIRE(static_cast<bool>(l >> id >> molecule >> type >> p[0] >> p[1] >> p[2]));
      REQUIRE(id == d.positions.size() + 1);
      CHECK((type >= 1 && type <= d.atom_types));
      d.positions.push_back(p);
    } else if (section == "Bonds") {
      std::size_t id = 0, type = 0, a = 0, b = 0;
      REQUIRE(static_cast<bool>(l >> id >> type >> a >> b));
      REQUIRE(id == d.pairs.size() + 1);
      CHECK((type >= 1 && type <= d.bond_types));
      REQUIRE((a >= 1 && a <= d.atoms && b >= 1 && b <= d.atoms && a != b));
      d.pairs.emplace_back(a - 1, b - 1);
    }
  }
  return d;
}

/// The edges of a soup's faces, each once, as sorted index pairs.
std::set<std::pair<std::size_t, std::size_t>> soup_edges(const PolygonSoup& soup) {
  std::set<std::pair<std::size_t, std::size_t>> edges;
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f)
    for (std::uint32_t k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) {
      const std::size_t u = soup.indices[k];
      const std::size_t v = soup.indices[k + 1 < soup.offsets[f + 1] ? k + 1 : soup.offsets[f]];
      edges.emplace(std::min(u, v), std::max(u, v));
    }
  return edges;
}

}  // namespace

TEST_CASE("LAMMPS data: an atom per point at its exact position, a bond per edge, all inside the box") {
  std::vector<std::pair<std::string, PolygonSoup>> soups;
  soups.emplace_back("torus", to_soup(test::make_torus(12, 8, 2.0, 0.5)));
  soups.emplace_back("sphere", to_soup(test::make_icosphere(2)));
  soups.emplace_back("cube of quads",
                     test::make_soup({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
                                     {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}}));
  // No edge, no Bonds section (the dual of one triangle); its bond type stays, for the same script.
  soups.emplace_back("one atom", test::make_soup({{1.0 / 3, 1.0 / 3, 0}}, {}));
  for (const auto& [name, soup] : soups) {
    INFO(name);
    const LammpsData d = parse_lammps(write_mesh(soup, Format::Lammps));
    CHECK(d.atom_types == 1);
    CHECK(d.bond_types == 1);
    REQUIRE(d.atoms == soup.points.size());
    REQUIRE(d.positions.size() == d.atoms);
    CHECK(d.pairs.size() == d.bonds);
    bool exact = true, inside = true;
    for (std::size_t i = 0; i < d.atoms; ++i)
      for (int k = 0; k < 3; ++k) {
        exact &= d.positions[i][k] == soup.points[i][k];
        inside &= d.lo[k] < d.positions[i][k] && d.positions[i][k] < d.hi[k];
      }
    CHECK(exact);
    CHECK(inside);
    // The bonds are the faces' edges, each once.
    const auto edges = soup_edges(soup);
    std::set<std::pair<std::size_t, std::size_t>> bonded;
    for (auto [a, b] : d.pairs) bonded.emplace(std::min(a, b), std::max(a, b));
    CHECK(bonded.size() == d.pairs.size());
    CHECK(bonded == edges);
  }
  // The counts of closed surfaces: E = V + F - chi (torus 0, sphere and cube 2).
  for (const auto& [soup, chi] : {std::pair{&soups[0].second, 0}, {&soups[1].second, 2}, {&soups[2].second, 2}}) {
    const std::size_t faces = soup->offsets.size() - 1;
    CHECK(parse_lammps(write_mesh(*soup, Format::Lammps)).bonds == soup->points.size() + faces - chi);
  }
  // Written only; its extensions name it.
  CHECK(parse_format("atoms.lammps") == Format::Lammps);
  CHECK(parse_format("ATOMS.LMP") == Format::Lammps);
  CHECK(parse_format("system.data") == Format::Lammps);
  CHECK_THROWS_WITH(read_mesh(write_mesh(soups[0].second, Format::Lammps), ReadOptions{Format::Lammps}),
                    Catch::Contains("unsupported input format lammps"));
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
