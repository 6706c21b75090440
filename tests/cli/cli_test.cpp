/// \file cli_test.cpp
/// The `remesh` executable as users run it: exit codes, one-line errors, and what it writes.

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "run_process.h"
#include "io/mesh_io.h"
#include "remesh/self_intersections.h"
#include "remesh/surface_distance.h"
#include "support/mesh_generators.h"

namespace fs = std::filesystem;
using remesh::TriMesh;
using remesh::test::ProcessResult;

namespace {

ProcessResult remesh_cli(const std::vector<std::string>& args) { return remesh::test::run_process(REMESH_BIN, args); }

/// A fresh directory for one test case, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    char name[] = "/tmp/remesh_cli_test_XXXXXX";
    path = mkdtemp(name);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

/// Writes OBJ by hand (not through the engine, which the tool itself uses).
void write_obj(const TriMesh& m, const std::string& path) {
  std::ofstream f(path);
  f.precision(17);
  for (auto v : m.vertices()) f << "v " << m.point(v)[0] << ' ' << m.point(v)[1] << ' ' << m.point(v)[2] << '\n';
  for (auto face : m.faces()) {
    f << 'f';
    for (auto v : m.fv_range(face)) f << ' ' << v.idx() + 1;
    f << '\n';
  }
}

struct ObjCounts {
  std::size_t vertices = 0, faces = 0;
  std::vector<std::size_t> face_sizes;
};

ObjCounts count_obj(const std::string& path) {
  std::ifstream f(path);
  ObjCounts c;
  std::string line;
  while (std::getline(f, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") ++c.vertices;
    if (tag == "f") {
      ++c.faces;
      std::size_t n = 0;
      std::string idx;
      while (s >> idx) ++n;
      c.face_sizes.push_back(n);
    }
  }
  return c;
}

std::size_t lines(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

std::string read_text(const std::string& path) {
  std::ifstream f(path);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

nlohmann::json info_json(const std::string& path) {
  const ProcessResult r = remesh_cli({"info", path, "--json"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(r.out);
}

}  // namespace

TEST_CASE("help and version", "[cli]") {
  const ProcessResult top = remesh_cli({"--help"});
  CHECK(top.exit_code == 0);
  for (const char* command : {"info", "convert", "dual", "--emin"}) CHECK(top.out.find(command) != std::string::npos);
  CHECK(remesh_cli({"--version"}).exit_code == 0);
  CHECK(remesh_cli({}).exit_code == 2);
  for (const char* command : {"info", "convert", "dual"}) {
    const ProcessResult r = remesh_cli({command, "--help"});
    CHECK(r.exit_code == 0);
    CHECK(r.out.find(std::string("remesh ") + command) != std::string::npos);
  }
}

TEST_CASE("bad arguments exit with 2 and one line on stderr", "[cli]") {
  TempDir dir;
  const std::string mesh = dir.file("sphere.obj");
  write_obj(remesh::test::make_icosphere(1), mesh);
  struct Case {
    std::vector<std::string> args;
    std::string mentions;
  };
  std::vector<Case> cases = {
      {{"info", mesh, "--bogus"}, "--bogus"},
      {{"info"}, "file"},
      {{"info", dir.file("missing.obj")}, "missing.obj"},
      {{"convert", mesh}, "file"},
      {{"convert", mesh, dir.file("out.xyzzy")}, "out.xyzzy"},
      {{"convert", mesh, dir.file("no_such_dir/out.obj")}, "no_such_dir"},
      // Found before the work, not after it: an output that is a directory, and a directory that
      // takes no file (/proc: even root cannot create one there).
      {{"convert", mesh, dir.file("taken.obj")}, "output is a directory"},
      {{"convert", mesh, "/proc/out.obj"}, "cannot write to the output directory /proc"},
      {{"dual", mesh, "/proc/d.obj"}, "/proc"},
      {{"dual", dir.file("missing.obj"), dir.file("d.obj")}, "missing.obj"},
      {{"frobnicate"}, "frobnicate"},
  };
  const std::string out = dir.file("out.obj");
  cases.push_back({{mesh, out, "--emax", "0.3"}, "--emin"});
  cases.push_back({{mesh, out, "--emin", "0.3"}, "--emax"});
  cases.push_back({{mesh, out, "--emin", "0.5", "--emax", "0.3"}, "--emax"});
  cases.push_back({{mesh, out, "--emin", "abc", "--emax", "0.3"}, "--emin"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--rings", "9"}, "--rings"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--bogus", "1"}, "--bogus"});
  cases.push_back({{dir.file("missing.obj"), out, "--emin", "0.2", "--emax", "0.3"}, "missing.obj"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--stats", dir.file("s.txt")}, "--stats"});
  fs::create_directory(dir.file("taken.obj"));
  cases.push_back({{mesh, "/proc/out.obj", "--emin", "0.2", "--emax", "0.3"}, "/proc"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--dual", "/proc/d.xyz"}, "/proc"});
  // The statistics file too: it was found unwritable only after the run (exit 1, the mesh written).
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--stats", "/proc/s.csv"}, "--stats: cannot write"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--stats", dir.file("no_such_dir/s.json")},
                   "--stats: output directory does not exist"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--stats", dir.file("taken.obj")}, "--stats"});
  // Numbers past the option's type say so (they read 'not a number' and 'outside -2147483648..').
  cases.push_back({{mesh, out, "--emin", "1e-400", "--emax", "0.3"}, "--emin: 1e-400 is beyond the range"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--iterations", "5000000000"}, "far too large"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--rings", "99999999999999999999"}, "far too large"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--threads", "4097"}, "outside 0..1024"});
  // An option where a value should be: the value was left out (it said "unexpected argument
  // 's.csv'", or that --emax was missing when it was given).
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--dual", "--stats", dir.file("s.csv")},
                   "option '--dual' needs a value (DUAL_OUT), but is followed by '--stats'"});
  cases.push_back({{mesh, out, "--emin", "--emax", "0.3"}, "option '--emin' needs a value"});
  cases.push_back({{mesh, out, "--emin", "0.2", "--emax", "0.3", "--dual", "--relax-dual"}, "followed by '--relax-dual'"});
  // The interval as the dual's bonds: each mistake named by the options given.
  cases.push_back({{mesh, out, "--bond-min", "0.1"}, "missing required option --bond-max"});
  cases.push_back({{mesh, out, "--bond-min", "0.1", "--bond-max", "0.2", "--emin", "0.2"}, "not both"});
  cases.push_back({{mesh, out, "--bond-min", "0.2", "--bond-max", "0.1"}, "--bond-max: must be greater than --bond-min"});
  cases.push_back({{mesh, out, "--bond-min", "x", "--bond-max", "0.1"}, "--bond-min: 'x' is not a number"});
  // The icosphere's bounding-box diagonal is 2 sqrt(3): edges of at least 2 * sqrt(3) (bonds of 2) cannot fit.
  cases.push_back({{mesh, out, "--bond-min", "2.5", "--bond-max", "3"}, "--bond-min: must be shorter than 2,"});
  cases.push_back({{mesh, out, "--emin", "4", "--emax", "5"}, "--emin: must be shorter than"});
  cases.push_back({{mesh, out, "--bond-min", "1", "--bond-max", "1.5e308"}, "--bond-max: is too large"});
  // A name longer than the file system takes (a long one it takes is written: the probe was
  // named after it, and too long itself).
  cases.push_back({{"convert", mesh, dir.file(std::string(300, 'a') + ".obj")}, "output file name too long"});
  for (const auto& c : cases) {
    std::string joined;
    for (const auto& a : c.args) joined += a + " ";
    const ProcessResult r = remesh_cli(c.args);
    INFO("remesh " << joined << "\nstderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(lines(r.err) == 1);
    CHECK(r.err.find(c.mentions) != std::string::npos);
  }
  CHECK(!fs::exists(dir.file("out.obj")));
  for (const auto& entry : fs::directory_iterator(dir.path))
    CHECK(entry.path().filename().string().find("remesh-probe") == std::string::npos);  // no probe left behind
  const std::string long_name = dir.file(std::string(240, 'a') + ".obj");
  CHECK(remesh_cli({"convert", mesh, long_name}).exit_code == 0);
  CHECK(fs::exists(long_name));
}

TEST_CASE("a bad input mesh exits with 3 and one line on stderr", "[cli]") {
  TempDir dir;
  std::vector<std::pair<std::string, std::string>> files = {
      {"garbage.obj", "this is not\na mesh at all\n"},
      {"garbage.ply", "ply\nformat nonsense 9.9\nend_header\n\x01\x02\x03"},
      {"garbage.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"},
      {"empty.stl", ""},
      {"bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"},
  };
  for (const auto& [name, content] : files) {
    const std::string path = dir.file(name);
    std::ofstream(path, std::ios::binary) << content;
    for (const char* command : {"info", "convert", "dual"}) {
      std::vector<std::string> args = {command, path};
      if (std::string(command) != "info") args.push_back(dir.file("out.obj"));
      const ProcessResult r = remesh_cli(args);
      INFO(command << " " << name << "\nstderr: " << r.err);
      CHECK(r.exit_code == 3);
      CHECK(lines(r.err) == 1);
    }
  }
  // A tetrahedron with two coincident corners reads as two triangles back to back: info describes
  // it, remesh and dual refuse it (remesh aborted on an OpenMesh assertion).
  const std::string pillow = dir.file("pillow.obj");
  std::ofstream(pillow) << "v 1 1 0.5\nv 0 0 0\nv 0 0 0\nv 1 0 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
  CHECK(remesh_cli({"info", pillow}).exit_code == 0);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{pillow, dir.file("out.obj"), "--emin", "0.3", "--emax", "0.5"},
        std::vector<std::string>{"dual", pillow, dir.file("out.obj")}}) {
    const ProcessResult r = remesh_cli(args);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 3);
    CHECK(lines(r.err) == 1);
  }
  // A device that never ends is refused at once, not read forever.
  const ProcessResult r = remesh_cli({"info", "/dev/zero"});
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("not a regular file") != std::string::npos);
}

TEST_CASE("info --json has the counts of a generated mesh", "[cli]") {
  TempDir dir;
  const TriMesh sphere = remesh::test::make_icosphere(2);
  const TriMesh grid = remesh::test::make_open_grid(6, 4, 1.0);
  write_obj(sphere, dir.file("sphere.obj"));
  write_obj(grid, dir.file("grid.obj"));

  const auto s = info_json(dir.file("sphere.obj"));
  CHECK(s.at("vertices") == sphere.n_vertices());
  CHECK(s.at("faces") == sphere.n_faces());
  CHECK(s.at("edges") == sphere.n_edges());
  CHECK(s.at("components") == 1);
  CHECK(s.at("boundary_loops") == 0);
  CHECK(s.at("euler") == 2);
  CHECK(s.at("repairs").empty());

  const auto g = info_json(dir.file("grid.obj"));
  CHECK(g.at("faces") == 6 * 4 * 2);
  CHECK(g.at("vertices") == 7 * 5);
  CHECK(g.at("boundary_loops") == 1);
  CHECK(g.at("euler") == 1);

  const ProcessResult text = remesh_cli({"info", dir.file("sphere.obj")});
  CHECK(text.exit_code == 0);
  CHECK(text.out.find(std::to_string(sphere.n_faces())) != std::string::npos);
}

TEST_CASE("info counts the faces that cross each other, or says the surface lies over itself", "[cli]") {
  TempDir dir;
  // Two balls overlapping (one mesh of two components): their faces cross along a circle.
  const TriMesh two = remesh::test::stacked_copies(remesh::test::make_icosphere(3), 2, remesh::Vec3(1.2, 0.013, 0.007));
  write_obj(two, dir.file("two.obj"));
  write_obj(remesh::test::make_icosphere(3), dir.file("one.obj"));
  // Sixteen copies of a ball at one place touch everywhere but cross nowhere (their faces share
  // their corners' positions); 1 024 overlap too much to count (over 20 million pairs of spheres).
  write_obj(remesh::test::stacked_copies(remesh::test::make_icosphere(2), 16), dir.file("stack.obj"));
  write_obj(remesh::test::stacked_copies(remesh::test::make_icosphere(1), 1024), dir.file("pile.obj"));
  const auto t = info_json(dir.file("two.obj"));
  CHECK(t.at("crossing_pairs") == remesh::find_self_intersections(two, 1).size());
  CHECK(t.at("crossing_pairs").get<std::size_t>() > 0);
  CHECK(t.at("layered") == false);
  CHECK(info_json(dir.file("one.obj")).at("crossing_pairs") == 0);
  const auto s = info_json(dir.file("stack.obj"));
  CHECK(s.at("crossing_pairs") == 0);
  CHECK(s.at("layered") == false);
  const auto p = info_json(dir.file("pile.obj"));
  CHECK(p.at("crossing_pairs").is_null());
  CHECK(p.at("layered") == true);
  const ProcessResult text = remesh_cli({"info", dir.file("two.obj")});
  CHECK(text.out.find("crossing faces  " + std::to_string(t.at("crossing_pairs").get<std::size_t>()) + " pairs") !=
        std::string::npos);
  CHECK(remesh_cli({"info", dir.file("pile.obj")}).out.find("not counted: too many faces overlap") != std::string::npos);
}

TEST_CASE("info reports repairs: a quad mesh is triangulated", "[cli]") {
  TempDir dir;
  const std::string path = dir.file("quads.obj");
  std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 5 6 3\n";
  const auto j = info_json(path);
  CHECK(j.at("faces") == 4);
  REQUIRE(!j.at("repairs").empty());
  const ProcessResult text = remesh_cli({"info", path});
  CHECK(text.out.find(j.at("repairs")[0].at("kind").get<std::string>()) != std::string::npos);
}

TEST_CASE("convert round trips obj -> ply/off/stl/glb/gltf -> obj keep the counts", "[cli]") {
  TempDir dir;
  const TriMesh torus = remesh::test::make_torus(16, 8, 2.0, 0.5);
  write_obj(torus, dir.file("torus.obj"));
  for (const char* ext : {"ply", "off", "stl", "glb", "gltf"}) {
    const std::string mid = dir.file(std::string("torus.") + ext);
    const std::string back = dir.file(std::string("back_") + ext + ".obj");
    const std::vector<std::string> first = {"convert", dir.file("torus.obj"), mid};
    const std::vector<std::string> second = {"convert", mid, back};
    INFO(ext);
    REQUIRE(remesh_cli(first).exit_code == 0);
    const ProcessResult r = remesh_cli(second);
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const ObjCounts c = count_obj(back);
    CHECK(c.vertices == torus.n_vertices());
    CHECK(c.faces == torus.n_faces());
    CHECK(info_json(back).at("euler") == 0);
  }
}

TEST_CASE("convert refuses coordinates STL, GLB and glTF cannot hold: exit 1, one line, nothing written", "[cli]") {
  TempDir dir;
  // A tetrahedron with corners at 1e308: it reads (doubles), but float32 ends near 3.4e38.
  std::ofstream(dir.file("far.obj")) << "v 0 0 0\nv 1e308 0 0\nv 0 1e308 0\nv 0 0 1e308\n"
                                        "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
  for (const char* name : {"far.stl", "far.glb", "far.gltf"}) {
    const ProcessResult r = remesh_cli({"convert", dir.file("far.obj"), dir.file(name)});
    INFO(name << "\nstderr: " << r.err);
    CHECK(r.exit_code == 1);
    CHECK(lines(r.err) == 1);
    CHECK(r.err.find("remesh: error: ") == 0);
    CHECK(r.err.find("point 1 (1e+308, 0, 0)") != std::string::npos);
    CHECK(r.err.find("float32, at most about 3.4e38") != std::string::npos);
    CHECK(!fs::exists(dir.file(name)));
  }
  // The double formats hold it.
  const ProcessResult r = remesh_cli({"convert", dir.file("far.obj"), dir.file("far.ply")});
  INFO(r.err);
  CHECK(r.exit_code == 0);
}

TEST_CASE("dual writes one polygon per interior vertex", "[cli]") {
  TempDir dir;
  const TriMesh grid = remesh::test::make_hex_lattice_patch(7, 8, 1.0);
  write_obj(grid, dir.file("lattice.obj"));
  std::size_t interior = 0;
  for (auto v : grid.vertices()) interior += grid.is_boundary(v) ? 0 : 1;
  const ProcessResult r = remesh_cli({"dual", dir.file("lattice.obj"), dir.file("dual.obj")});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const ObjCounts c = count_obj(dir.file("dual.obj"));
  CHECK(c.faces == interior);
  CHECK(c.vertices == grid.n_faces());
  for (auto n : c.face_sizes) CHECK(n == 6);
  // The summary: one atom per triangle, every ring a hexagon, bonds of 1 / sqrt(3) (equilateral
  // triangles of side 1).
  CHECK(r.err.find(std::to_string(grid.n_faces()) + " atoms, ") != std::string::npos);
  CHECK(r.err.find("rings: " + std::to_string(interior) + " of 6 sides\n") != std::string::npos);
  CHECK(r.err.find("bond length:          mean 0.57735, deviation ") != std::string::npos);
  CHECK(r.err.find(", min 0.57735, max 0.57735\n") != std::string::npos);

  REQUIRE(remesh_cli({"dual", dir.file("lattice.obj"), dir.file("dual.xyz")}).exit_code == 0);
  CHECK(lines(read_text(dir.file("dual.xyz"))) >= grid.n_faces());
  REQUIRE(remesh_cli({"dual", dir.file("lattice.obj"), dir.file("dual.glb")}).exit_code == 0);
  CHECK(fs::file_size(dir.file("dual.glb")) > 0);
  // LAMMPS data: an atom per triangle, and a bond per side of the dual's polygons: across each
  // interior edge of the grid with an interior end (an edge between two boundary vertices lies
  // around no interior vertex, so no polygon has its dual edge).
  REQUIRE(remesh_cli({"dual", dir.file("lattice.obj"), dir.file("dual.lmp")}).exit_code == 0);
  const std::string data = read_text(dir.file("dual.lmp"));
  std::size_t interior_edges = 0;
  for (auto e : grid.edges()) {
    const auto h = grid.halfedge_handle(e, 0);
    interior_edges += !grid.is_boundary(e) && !(grid.is_boundary(grid.from_vertex_handle(h)) &&
                                                grid.is_boundary(grid.to_vertex_handle(h)));
  }
  std::string counts = std::to_string(grid.n_faces()) + " atoms\n";
  counts += std::to_string(interior_edges) + " bonds\n";
  CHECK(data.find("\n\n" + counts) != std::string::npos);
}

TEST_CASE("a short remesh run writes the mesh, the dual and one stats row per iteration", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(2), dir.file("sphere.obj"));
  const std::string out = dir.file("out.obj"), dual = dir.file("dual.obj");
  const ProcessResult r = remesh_cli({dir.file("sphere.obj"), out, "--emin", "0.1", "--emax", "0.15", "--iterations",
                                      "4", "--all-iterations", "--protect-tips", "--keep-creases", "--more-regular", "--stats", dir.file("stats.csv"), "--dual", dual,
                                      "--threads", "2"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("completed") != std::string::npos);
  CHECK(r.out.find("\n  triangles:            angles ") != std::string::npos);
  {
    // How far the result lies from the sphere: the written result against the input, both sides.
    const std::string key = "\n  distance to input:    ";
    const auto at = r.out.find(key);
    REQUIRE(at != std::string::npos);
    const double printed = std::stod(r.out.substr(at + key.size()));
    const remesh::SurfaceDistance d =
        remesh::surface_distance(remesh::read_mesh_file(out).mesh, remesh::test::make_icosphere(2), 1);
    CHECK(printed == Approx(d.hausdorff()).epsilon(1e-3));  // printed to 4 digits
    CHECK(printed > 0);
  }
  const auto j = info_json(out);
  CHECK(j.at("euler") == 2);
  CHECK(j.at("boundary_loops") == 0);
  CHECK(j.at("faces") > 320);  // refined: the sphere's edges are longer than 0.15

  const std::string csv = read_text(dir.file("stats.csv"));
  std::istringstream rows(csv);
  std::string header, line;
  std::getline(rows, header);
  CHECK(header.rfind("iteration,vertices,edges,mean,deviation,regular_percent,small,big,inside_fraction", 0) == 0);
  int n = 0;
  while (std::getline(rows, line)) {
    ++n;
    CHECK(line.rfind(std::to_string(n) + ",", 0) == 0);
  }
  CHECK(n == 4);

  const ObjCounts d = count_obj(dual);
  CHECK(d.vertices == j.at("faces").get<std::size_t>());
  CHECK(d.faces == j.at("vertices").get<std::size_t>());
  // The summary describes that dual: its atoms and bonds, and the bonds against [0.1, 0.15] / sqrt(3).
  CHECK(r.out.find("dual:                 " + std::to_string(d.vertices) + " atoms, " +
                   std::to_string(j.at("edges").get<std::size_t>()) + " bonds; rings: ") != std::string::npos);
  CHECK(r.out.find("bonds inside [0.057735, 0.0866025] = [e_min, e_max] / sqrt(3): ") != std::string::npos);

  const ProcessResult quiet = remesh_cli({dir.file("sphere.obj"), out, "--emin", "0.1", "--emax", "0.15",
                                          "--iterations", "2", "--quiet", "--stats", dir.file("stats.json")});
  CHECK(quiet.exit_code == 0);
  CHECK(quiet.out.empty());
  const auto stats = nlohmann::json::parse(read_text(dir.file("stats.json")));
  REQUIRE(stats.is_array());
  REQUIRE(!stats.empty());
  CHECK(stats.size() <= 2);
  CHECK(stats.back().contains("max_projection_distance"));
  // The extension in any case, as OUT's (.CSV was refused).
  const ProcessResult upper = remesh_cli({dir.file("sphere.obj"), dir.file("OUT.OBJ"), "--emin", "0.1", "--emax", "0.15",
                                          "--iterations", "2", "--quiet", "--stats", dir.file("S.JSON")});
  CHECK(upper.exit_code == 0);
  CHECK(nlohmann::json::parse(read_text(dir.file("S.JSON"))).is_array());
}

TEST_CASE("remesh --relax-dual puts more of the dual's bonds inside the bond interval, and needs --dual", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(3), dir.file("sphere.obj"));
  // The share of bonds inside, from the summary line "bonds inside [..] = [e_min, e_max] / sqrt(3): X %".
  auto bonds_inside = [](const std::string& out) {
    const std::string key = "= [e_min, e_max] / sqrt(3): ";
    const std::size_t at = out.find(key);
    REQUIRE(at != std::string::npos);
    return std::stod(out.substr(at + key.size()));
  };
  // A tight interval (+- 10 %) around the sphere's mean edge.
  std::vector<std::string> args = {dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "0.14", "--emax", "0.17",
                                   "--dual", dir.file("dual.obj")};
  const ProcessResult plain = remesh_cli(args);
  INFO(plain.err);
  REQUIRE(plain.exit_code == 0);
  args.push_back("--relax-dual");
  const ProcessResult relaxed = remesh_cli(args);
  INFO(relaxed.err);
  REQUIRE(relaxed.exit_code == 0);
  INFO("bonds inside: " << bonds_inside(plain.out) << " % -> " << bonds_inside(relaxed.out) << " %");
  CHECK(bonds_inside(relaxed.out) > bonds_inside(plain.out) + 5);
  CHECK(bonds_inside(relaxed.out) > 97);
  CHECK(relaxed.out.find("  bonds relaxed:        ") != std::string::npos);
  CHECK(plain.out.find("bonds relaxed") == std::string::npos);

  const ProcessResult alone = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "0.14", "--emax",
                                          "0.17", "--relax-dual"});
  CHECK(alone.exit_code == 2);
  CHECK(alone.err.find("--relax-dual") != std::string::npos);
  CHECK(std::count(alone.err.begin(), alone.err.end(), '\n') == 1);
}

TEST_CASE("an interval of bonds, --bond-min and --bond-max, runs as --emin and --emax times sqrt(3)", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(3), dir.file("sphere.obj"));
  char edge_min[32], edge_max[32];
  std::snprintf(edge_min, sizeof edge_min, "%.17g", 0.08 * std::sqrt(3.0));
  std::snprintf(edge_max, sizeof edge_max, "%.17g", 0.1 * std::sqrt(3.0));
  const ProcessResult by_edges = remesh_cli({dir.file("sphere.obj"), dir.file("e.obj"), "--emin", edge_min, "--emax",
                                             edge_max, "--dual", dir.file("e_dual.obj"), "--iterations", "8"});
  const ProcessResult by_bonds = remesh_cli({dir.file("sphere.obj"), dir.file("b.obj"), "--bond-min", "0.08",
                                             "--bond-max", "0.1", "--dual", dir.file("b_dual.obj"), "--iterations", "8"});
  INFO(by_edges.err << by_bonds.err);
  REQUIRE(by_edges.exit_code == 0);
  REQUIRE(by_bonds.exit_code == 0);
  auto bytes = [](const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), {});
  };
  CHECK(bytes(dir.file("b.obj")) == bytes(dir.file("e.obj")));
  CHECK(bytes(dir.file("b_dual.obj")) == bytes(dir.file("e_dual.obj")));
  CHECK_FALSE(bytes(dir.file("b.obj")).empty());
  // The summary judges the bonds against the interval given.
  CHECK(by_bonds.out.find("bonds inside [0.08, 0.1] = [e_min, e_max] / sqrt(3)") != std::string::npos);
}

TEST_CASE("the summary says how many edges outside lie in parts too thin for the interval", "[cli]") {
  TempDir dir;
  // A torus whose tube is 0.5 across: no ring of edges of at least 1.2 follows it.
  write_obj(remesh::test::make_torus(48, 8, 4.0, 0.25), dir.file("thin.obj"));
  const ProcessResult r = remesh_cli({dir.file("thin.obj"), dir.file("out.obj"), "--emin", "1.2", "--emax", "1.8",
                                      "--iterations", "10"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto at = r.out.find("in thin parts:");
  REQUIRE(at != std::string::npos);
  // "N of the N edges outside": every edge outside lies on the thin tube.
  std::istringstream line(r.out.substr(at + std::string("in thin parts:").size()));
  std::size_t thin = 0, outside = 0;
  std::string of, the;
  line >> thin >> of >> the >> outside;
  CHECK(thin > 0);
  CHECK(thin == outside);
  // And how many of them have an end of irregular valence: "M of the N edges outside".
  const auto irregular_at = r.out.find("irregular valence:");
  REQUIRE(irregular_at != std::string::npos);
  std::istringstream irregular_line(r.out.substr(irregular_at + std::string("irregular valence:").size()));
  std::size_t irregular = 0, outside_again = 0;
  irregular_line >> irregular >> of >> the >> outside_again;
  CHECK(outside_again == outside);
  CHECK(irregular <= outside);
  // A sphere whose edges all fit has no such line.
  write_obj(remesh::test::make_icosphere(3, 4.0), dir.file("sphere.obj"));
  const ProcessResult s = remesh_cli({dir.file("sphere.obj"), dir.file("out2.obj"), "--emin", "1.2", "--emax", "1.8"});
  REQUIRE(s.exit_code == 0);
  CHECK(s.out.find("100.000 %") != std::string::npos);
  CHECK(s.out.find("in thin parts") == std::string::npos);
  CHECK(s.out.find("irregular valence") == std::string::npos);
  // Nor do its faces cross each other; the line says so.
  CHECK(s.out.find("  crossing faces:       0 pairs\n") != std::string::npos);
}

TEST_CASE("the summary splits the regular vertices by the input's thickness", "[cli]") {
  TempDir dir;
  // A lens: a sphere of radius 6 flattened to 3 across at its middle and 0 at its rim, so that
  // vertices lie both where it is thinner than 2 e_max = 2.8 and where it is not.
  remesh::TriMesh lens = remesh::test::make_icosphere(4, 6.0);
  for (auto v : lens.vertices()) lens.point(v)[2] *= 0.25;
  write_obj(lens, dir.file("lens.obj"));
  const ProcessResult r = remesh_cli({dir.file("lens.obj"), dir.file("out.obj"), "--emin", "1.0", "--emax", "1.4"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  // "  by thickness:         X % where the input is at least 2.8 = 2 e_max thick, Y % of the N
  // vertices in thinner parts (...)"
  const auto at = r.out.find("  by thickness:");
  REQUIRE(at != std::string::npos);
  std::istringstream line(r.out.substr(at + std::string("  by thickness:").size()));
  double thick = -1, thin = -1, limit = 0;
  std::size_t n = 0;
  std::string word;
  line >> thick >> word >> word >> word >> word >> word >> word >> word >> limit;
  for (int i = 0; i < 4; ++i) line >> word;  // "= 2 e_max thick,"
  line >> thin >> word >> word >> word >> n;
  CHECK(limit == Approx(2.8));
  CHECK(n > 0);
  CHECK(thick >= 0);
  CHECK(thick <= 100);
  CHECK(thin >= 0);
  CHECK(thin <= 100);
  // The share over all vertices lies between the two (every vertex of this mesh is measured).
  const auto regular_at = r.out.find("  regular vertices:");
  REQUIRE(regular_at != std::string::npos);
  const double all = std::stod(r.out.substr(regular_at + std::string("  regular vertices:").size()));
  CHECK(all >= std::min(thick, thin) - 0.01);
  CHECK(all <= std::max(thick, thin) + 0.01);
}

TEST_CASE("the summary says where the time went, step by step, adding up to the run's seconds", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(3, 4.0), dir.file("sphere.obj"));
  const ProcessResult r = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "1.2", "--emax", "1.8"});
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto outcome = r.out.find(" iterations, ");
  REQUIRE(outcome != std::string::npos);
  const double total = std::stod(r.out.substr(outcome + std::string(" iterations, ").size()));
  const auto at = r.out.find("seconds by step:");
  REQUIRE(at != std::string::npos);
  // "stellar 0.012, flips 0.010, ..., other 0.001"
  std::istringstream line(r.out.substr(at + std::string("seconds by step:").size(), r.out.find('\n', at) - at));
  std::vector<std::string> names;
  double sum = 0;
  std::string name, value;
  while (line >> name >> value) {
    names.push_back(name);
    const double seconds = std::stod(value);
    CHECK(seconds >= 0);
    sum += seconds;
  }
  CHECK(names == std::vector<std::string>{"stellar", "flips", "filter", "projection", "guards", "cleanup", "snap",
                                          "untangle", "setup", "other"});
  // Ten figures rounded to 0.001 s against the total rounded to 0.01 s.
  CHECK(std::abs(sum - total) <= 0.011);
}

TEST_CASE("remesh reports every bad option value at once, one line each", "[cli]") {
  TempDir dir;
  const std::string mesh = dir.file("sphere.obj"), out = dir.file("out.obj");
  write_obj(remesh::test::make_icosphere(1), mesh);
  struct Case {
    std::vector<std::string> options;
    std::vector<std::string> lines;  ///< each must be on a line of its own
  };
  const std::vector<Case> cases = {
      // Two values that do not parse, and a range error of one that does.
      {{"--emin", "abc", "--emax", "xyz", "--rings", "9"},
       {"--emin: 'abc' is not a number", "--emax: 'xyz' is not a number", "--rings: "}},
      // Not an integer, outside the parser's range, outside check()'s range.
      {{"--emin", "0.2", "--emax", "0.3", "--iterations", "1.5", "--threads", "99999", "--flip-factor", "2"},
       {"--iterations: '1.5' is not an integer", "--threads: 99999 is outside 0..1024", "--flip-factor: "}},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = {mesh, out};
    args.insert(args.end(), c.options.begin(), c.options.end());
    const ProcessResult r = remesh_cli(args);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(lines(r.err) == c.lines.size());
    std::istringstream err(r.err);
    std::vector<std::string> printed;
    for (std::string line; std::getline(err, line);) printed.push_back(line);
    for (const auto& expected : c.lines) {
      INFO(expected);
      CHECK(std::count_if(printed.begin(), printed.end(), [&](const std::string& line) {
              return line.rfind("remesh: ", 0) == 0 && line.find(expected) != std::string::npos;
            }) == 1);
    }
  }
  CHECK(!fs::exists(out));
}

TEST_CASE("remesh refuses two outputs naming the same file before the run, and may write over IN", "[cli]") {
  TempDir dir;
  const std::string in = dir.file("sphere.obj"), out = dir.file("out.obj");
  write_obj(remesh::test::make_icosphere(1), in);
  fs::create_directory(dir.file("sub"));
  auto refused = [&](const std::vector<std::string>& outputs, const std::string& mentions) {
    std::vector<std::string> args = {in, "--emin", "0.2", "--emax", "0.3", "--iterations", "1"};
    args.insert(args.end(), outputs.begin(), outputs.end());
    const ProcessResult r = remesh_cli(args);
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 2);
    CHECK(lines(r.err) == 1);
    CHECK(r.err.find(mentions) != std::string::npos);
  };

  // OUT and --dual, however spelled: nothing is written.
  refused({out, "--dual", out}, "--dual names the same file as OUT: " + out);
  refused({out, "--dual", (dir.path / "." / "out.obj").string()}, "--dual names the same file as OUT");
  refused({out, "--dual", (dir.path / "sub" / ".." / "out.obj").string()}, "--dual names the same file as OUT");
  refused({(dir.path / "sub" / ".." / "out.obj").string(), "--dual", out, "--stats", dir.file("s.csv")},
          "--dual names the same file as OUT");
  CHECK(!fs::exists(out));
  CHECK(!fs::exists(dir.file("s.csv")));

  // --stats and OUT through a symbolic link, to a file not written yet and to one written before.
  fs::create_symlink(out, dir.file("link.csv"));
  refused({out, "--stats", dir.file("link.csv")}, "--stats names the same file as OUT");
  CHECK(!fs::exists(out));
  std::ofstream(out) << "earlier\n";
  refused({out, "--stats", dir.file("link.csv")}, "--stats names the same file as OUT");
  CHECK(read_text(out) == "earlier\n");

  // --stats and --dual through a hard link.
  const std::string dual = dir.file("dual.obj");
  std::ofstream(dual) << "earlier dual\n";
  fs::create_hard_link(dual, dir.file("hard.json"));
  refused({dir.file("other.obj"), "--dual", dual, "--stats", dir.file("hard.json")},
          "--stats names the same file as --dual");
  CHECK(read_text(dual) == "earlier dual\n");
  CHECK(!fs::exists(dir.file("other.obj")));

  // The dual over IN, whatever spelling: refused before anything is written (it replaced the input).
  const std::string before = read_text(in);
  refused({out, "--dual", (dir.path / "sub" / ".." / "sphere.obj").string()}, "--dual names the input file");
  const ProcessResult dual_over_in = remesh_cli({"dual", in, (dir.path / "." / "sphere.obj").string()});
  CHECK(dual_over_in.exit_code == 2);
  CHECK(dual_over_in.err.find("OUT names the input file") != std::string::npos);
  CHECK(read_text(in) == before);

  // OUT over IN stays allowed: IN is read before anything is written.
  const std::string both = dir.file("both.obj");
  fs::copy_file(in, both);
  const ProcessResult r = remesh_cli({both, (dir.path / "." / "both.obj").string(), "--emin", "0.2", "--emax", "0.3",
                                      "--iterations", "2", "--quiet"});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(info_json(both).at("faces") > 80);  // refined: the icosphere's 80 faces have edges over 0.3
}

TEST_CASE("a job over --max-faces is refused with exit 3", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(2), dir.file("sphere.obj"));
  // The input has 320 faces: over a limit of 100 already.
  ProcessResult r = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "0.2", "--emax", "0.3",
                                "--max-faces", "100"});
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  // Edges of 0.001-0.002 on the unit sphere would need millions of faces.
  r = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "0.001", "--emax", "0.002", "--max-faces",
                  "100000"});
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK(!fs::exists(dir.file("out.obj")));
  // Past the estimate's cap (e_max 1e-300: the count is no count) it says "over".
  r = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--emin", "1e-300", "--emax", "2e-300"});
  CHECK(r.exit_code == 3);
  CHECK(r.err.find("estimated output of over 1000000000000000000 faces") != std::string::npos);
  // Given as bonds, the advice names the option given.
  r = remesh_cli({dir.file("sphere.obj"), dir.file("out.obj"), "--bond-min", "0.0001", "--bond-max", "0.0002"});
  CHECK(r.exit_code == 3);
  CHECK(lines(r.err) == 1);
  CHECK(r.err.find("(--bond-max too small for this mesh)") != std::string::npos);
}

TEST_CASE("output piped into a program that exits early does not stop the run", "[cli]") {
  // `remesh ... | head -1`: SIGPIPE ended the run (exit 141) before the mesh was written.
  TempDir dir;
  write_obj(remesh::test::make_icosphere(3), dir.file("sphere.obj"));
  const std::string out = dir.file("out.obj"), rc = dir.file("rc");
  const std::string command = "( '" + std::string(REMESH_BIN) + "' '" + dir.file("sphere.obj") + "' '" + out +
                              "' --emin 0.1 --emax 0.15 --iterations 10; echo $? > '" + rc + "' ) | head -c 1 > /dev/null";
  REQUIRE(std::system(command.c_str()) == 0);
  CHECK(read_text(rc) == "0\n");
  CHECK(info_json(out).at("euler") == 2);
}

TEST_CASE("Ctrl-C stops the run and the partial mesh is still written", "[cli]") {
  TempDir dir;
  write_obj(remesh::test::make_icosphere(3), dir.file("sphere.obj"));
  const std::string out = dir.file("out.obj");
  // 1000 iterations that never converge (the interval is narrow) would take far longer than the
  // 400 ms after which SIGINT arrives.
  const ProcessResult r = remesh::test::run_process(
      REMESH_BIN,
      {dir.file("sphere.obj"), out, "--emin", "0.05", "--emax", "0.0505", "--iterations", "1000", "--all-iterations",
       "--stats", dir.file("stats.json"), "--threads", "1"},
      400);
  INFO(r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.err.find("cancelled") != std::string::npos);
  CHECK(r.out.find("cancelled") != std::string::npos);
  const auto j = info_json(out);
  CHECK(j.at("euler") == 2);
  const auto stats = nlohmann::json::parse(read_text(dir.file("stats.json")));
  CHECK(stats.size() < 1000);
}
