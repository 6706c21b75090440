// Truncated and byte-flipped files in every input format: an error (MeshError / LimitError) or a
// valid mesh, never a crash, a hang or another exception type. Meshes with vertices snapped into
// zero-area faces: a valid mesh without them. Also built with ASan + UBSan.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "io/mesh_io.h"
#include "io/point_hash.h"
#include "io_test_util.h"
#include "support/mesh_generators.h"

using namespace remesh;

namespace {

struct Outcome {
  std::size_t errors = 0, meshes = 0;
};

/// Reads one variant; FAILs on an unexpected exception type or an invalid mesh.
void try_variant(const std::string& bytes, std::optional<Format> format, const std::string& what, Outcome& out,
                 bool weld = false) {
  ReadOptions o;
  o.format = format;
  o.weld = weld;
  try {
    LoadedMesh m = read_mesh(bytes, o);
    const std::string problem = test::check_loaded(m.mesh);
    if (!problem.empty()) FAIL(what << ": invalid mesh accepted: " << problem);
    ++out.meshes;
  } catch (const MeshError& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) FAIL(what << ": multi-line message: " << e.what());
    ++out.errors;
  } catch (const LimitError&) {
    ++out.errors;
  } catch (const std::exception& e) {
    FAIL(what << ": unexpected exception: " << e.what());
  }
}

/// Reads `bytes` truncated (every length near both ends, ~150 between) and with 1 to 4 bytes
/// changed (300 variants), given their format or not, some welded.
void garble(const std::string& bytes, Format format, const std::string& name, std::mt19937& rng,
            Outcome& outcome) {
  const std::size_t n = bytes.size();
  // Truncations: every length near both ends, then ~150 spread over the file.
  for (std::size_t len = 0; len < n; len += (len < 64 || len + 64 > n) ? 1 : std::max<std::size_t>(1, n / 150)) {
    const std::string cut = bytes.substr(0, len);
    try_variant(cut, len % 2 ? std::optional<Format>(format) : std::nullopt,
                name + " truncated to " + std::to_string(len), outcome);
  }
  // Byte flips: 1 to 4 random bytes set to random values (half of them to "interesting" ones).
  const unsigned char interesting[] = {0, 0xff, 0x7f, 0x80, '0', '9', '-', '.', 'e', ' ', '\n', '/', '#', '"', '{'};
  for (int variant = 0; variant < 300; ++variant) {
    std::string bad = bytes;
    const int flips = 1 + variant % 4;
    std::string where;
    for (int k = 0; k < flips; ++k) {
      const std::size_t at = std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
      const unsigned v = rng();
      bad[at] = static_cast<char>(v % 2 ? interesting[(v >> 1) % sizeof interesting] : (v >> 8) & 0xff);
      where += ' ';
      where += std::to_string(at);
    }
    try_variant(bad, variant % 3 ? std::optional<Format>(format) : std::nullopt,
                name + " with bytes changed at" + where, outcome, variant % 4 == 1);
  }
}

/// garble() on its own stream: some variants must fail to read and some must read.
void check_garbled(const std::string& bytes, Format format, const std::string& name, unsigned seed) {
  std::mt19937 rng(seed);
  Outcome outcome;
  garble(bytes, format, name, rng, outcome);
  CHECK(outcome.errors > 0);
  CHECK(outcome.meshes > 1);
}

}  // namespace

TEST_CASE("Garbled files give an error or a valid mesh") {
  const PolygonSoup soup = to_soup(test::make_icosphere(1));
  std::mt19937 rng(20261122);
  for (const test::SampleFile& file : test::sample_files(soup)) {
    INFO(file.name);
    Outcome outcome;
    // The intact file reads.
    try_variant(file.bytes, file.format, file.name + " intact", outcome);
    REQUIRE(outcome.meshes == 1);
    garble(file.bytes, file.format, file.name, rng, outcome);
    CHECK(outcome.errors > 0);
    CHECK(outcome.meshes > 1);
  }
}

TEST_CASE("Garbled OFF with its records wrapped over lines gives an error or a valid mesh") {
  // An icosphere's ASCII OFF with every value on a line of its own (the counts too), a comment and
  // a blank line after every 7th: the reader carries records over lines, here under ASan too.
  const PolygonSoup soup = to_soup(test::make_icosphere(1));
  const std::string off = write_mesh(soup, Format::Off);
  REQUIRE(off.rfind("OFF\n", 0) == 0);
  std::string wrapped = "OFF\n";
  std::size_t spaces = 0;
  for (char c : off.substr(4)) {
    if (c == ' ')
      wrapped += ++spaces % 7 ? "\n" : " # wrapped\n\n";
    else
      wrapped += c;
  }
  REQUIRE(spaces > 300);
  const LoadedMesh plain = read_mesh(off);
  LoadedMesh m;
  REQUIRE_NOTHROW(m = read_mesh(wrapped));
  REQUIRE(m.mesh.n_faces() == plain.mesh.n_faces());
  for (auto v : plain.mesh.vertices()) CHECK(m.mesh.point(v) == plain.mesh.point(v));
  check_garbled(wrapped, Format::Off, "wrapped off", 20260311);
}

TEST_CASE("Garbled OBJ with star-shaped caps of 300 sides gives an error or a valid mesh") {
  // A prism whose caps are star-shaped 300-gons: polygons past 256 sides take the large ear
  // clipping (triangulate.cpp), here under ASan too, with corners moved and indices broken.
  const double pi = std::acos(-1.0);
  constexpr int n = 300;
  std::string obj;
  char line[96];
  for (int z = 0; z < 2; ++z)
    for (int i = 0; i < n; ++i) {
      const double t = 2 * pi * i / n, r = i % 2 ? 0.7 : 1.0;
      std::snprintf(line, sizeof line, "v %.6f %.6f %d\n", r * std::cos(t), r * std::sin(t), z);
      obj += line;
    }
  obj += "f";
  for (int i = n; i >= 1; --i) obj += ' ' + std::to_string(i);
  obj += "\nf";
  for (int i = 1; i <= n; ++i) obj += ' ' + std::to_string(n + i);
  obj += '\n';
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    std::snprintf(line, sizeof line, "f %d %d %d %d\n", i + 1, j + 1, n + j + 1, n + i + 1);
    obj += line;
  }
  LoadedMesh m;
  REQUIRE_NOTHROW(m = read_mesh(obj));
  CHECK(m.mesh.n_faces() == 2 * (n - 2) + 2 * n);
  CHECK(test::euler_characteristic(m.mesh) == 2);
  check_garbled(obj, Format::Obj, "star prism obj", 20261127);
}

TEST_CASE("Vertices snapped onto a neighbour or an edge give a valid mesh without zero-area faces") {
  // Needles (a vertex onto a neighbour, exactly or 1e-14 off) and caps (a vertex onto the segment
  // between two neighbours), several at random, some touching: the mesh read is valid with no
  // zero-area face, and has the original topology unless the reader reports faces dropped.
  std::mt19937 rng(20261126);
  const std::pair<const char*, TriMesh> meshes[] = {{"icosphere", test::make_icosphere(2)},
                                                    {"torus", test::make_torus(16, 8, 1.0, 0.4)},
                                                    {"open grid", test::make_open_grid(8, 8, 1.0)}};
  for (const auto& [name, mesh] : meshes) {
    INFO(name);
    const PolygonSoup original = to_soup(mesh);
    const long euler = test::euler_characteristic(mesh);
    const std::size_t loops = test::count_boundary_loops(mesh);
    std::size_t whole = 0, trials = 300;
    for (std::size_t trial = 0; trial < trials; ++trial) {
      PolygonSoup soup = original;
      const int snaps = 1 + static_cast<int>(rng() % 8);
      std::string what;
      for (int s = 0; s < snaps; ++s) {
        const auto v = mesh.vertex_handle(static_cast<unsigned>(rng() % mesh.n_vertices()));
        std::vector<TriMesh::VertexHandle> ring;
        for (auto w : mesh.vv_ccw_range(v)) ring.push_back(w);
        const std::size_t i = rng() % ring.size();
        const Vec3 &a = soup.points[ring[i].idx()], &b = soup.points[ring[(i + 1) % ring.size()].idx()];
        const unsigned mode = rng() % 3;
        const double t = 0.1 + 0.8 * (rng() % 1000) / 1000.0;
        soup.points[v.idx()] = mode == 0 ? a : mode == 1 ? a * (1 + 1e-14) : a + (b - a) * t;
        what += ' ';
        what += std::to_string(v.idx());
        what += ':';
        what += std::to_string(mode);
      }
      INFO("trial " << trial << ", vertex:mode" << what);
      LoadedMesh m;
      REQUIRE_NOTHROW(m = read_mesh(write_mesh(soup, Format::Obj)));
      CHECK(test::check_loaded(m.mesh) == "");
      const bool dropped = std::any_of(m.repairs.begin(), m.repairs.end(),
                                       [](const Repair& r) { return r.kind == "degenerate_faces_removed"; });
      if (dropped) continue;
      ++whole;
      CHECK(test::euler_characteristic(m.mesh) == euler);
      CHECK(test::count_boundary_loops(m.mesh) == loops);
    }
    // Most repairs keep the surface whole; where a snap folds the open grid, some zero-area faces
    // allow no collapse, flip or deletion (1484 of 1500 trials whole, the spheres and tori all).
    INFO(whole << " of " << trials << " read whole");
    CHECK(whole * 10 >= trials * 9);
  }
}

TEST_CASE("Extreme integers where the text formats read indices and counts give an error, not overflow") {
  // Under UBSan (test_io_asan) an overflowing negation or sum aborts the test. The OBJ reader
  // negated a relative index of -2^63 to compare it with the vertex count.
  const std::string extremes[] = {"-9223372036854775808", "-9223372036854775807", "9223372036854775807",
                                  "18446744073709551615", "-4", "4294967296", "-4294967296"};
  for (const std::string& x : extremes) {
    INFO(x);
    Outcome outcome;
    const std::string vertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    try_variant(vertices + "f 1 2 " + x + "\n", Format::Obj, "obj face index " + x, outcome);
    try_variant(vertices + "f " + x + "/1/1 2/1/1 3/1/1\n", Format::Obj, "obj face index with slashes " + x, outcome);
    try_variant("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 " + x + "\n", Format::Off, "off face index " + x, outcome);
    try_variant("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n" + x + " 0 1 2\n", Format::Off, "off face size " + x, outcome);
    try_variant("OFF\n" + x + " 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", Format::Off, "off vertex count " + x, outcome);
    try_variant("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 " +
                    x + "\n",
                Format::Ply, "ply face index " + x, outcome);
    try_variant("ply\nformat ascii 1.0\nelement vertex " + x +
                    "\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
                Format::Ply, "ply vertex count " + x, outcome);
    CHECK(outcome.meshes == 0);
  }
}

TEST_CASE("Corners crafted to share one hash under an unkeyed mix spread over the welders' buckets") {
  // The welders' old hash, h = ((h ^ b) * P) ^ (h >> 29) over the three coordinates' bits, can be
  // inverted: pick x and y, solve for the bits of z that give any chosen value T. An ASCII STL of
  // 200 000 such corners took 67 s to read (every insert walked one bucket chain); point_hash is
  // keyed per process, so the same corners land in buckets as random ones would.
  constexpr std::uint64_t kPrime = 1099511628211ull, kBasis = 1469598103934665603ull, kTarget = 0x0123456789abcdefull;
  std::uint64_t inverse = kPrime;  // Newton's iteration for the inverse modulo 2^64
  for (int i = 0; i < 6; ++i) inverse *= 2 - kPrime * inverse;
  REQUIRE(kPrime * inverse == 1);
  auto step = [&](std::uint64_t h, std::uint64_t b) { return ((h ^ b) * kPrime) ^ (h >> 29); };
  auto bits = [](double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, 8);
    return b;
  };
  std::vector<std::array<std::uint64_t, 3>> corners;
  for (int i = 1; corners.size() < 2000; ++i) {
    const std::uint64_t bx = bits(i), by = bits(i % 7);
    const std::uint64_t h = step(step(kBasis, bx), by);
    const std::uint64_t bz = h ^ ((kTarget ^ (h >> 29)) * inverse);
    double z;
    std::memcpy(&z, &bz, 8);
    if (!std::isfinite(z) || z == 0) continue;
    REQUIRE(step(h, bz) == kTarget);  // all share the old hash
    corners.push_back({bx, by, bz});
  }
  constexpr std::uint64_t kBuckets = 10007;
  std::vector<bool> used(kBuckets, false);
  std::size_t distinct = 0;
  for (const auto& c : corners) {
    const std::uint64_t b = io::point_hash(c.data()) % kBuckets;
    distinct += !used[b];
    used[b] = true;
  }
  // 2 000 random keys in 10 007 buckets fill about 1 813 of them.
  CHECK(distinct >= 1600);
  // And they are read as 2 000 distinct corners.
  std::string stl = "solid c\n";
  for (std::size_t k = 0; k + 2 < corners.size(); k += 3) {
    stl += "facet normal 0 0 0\nouter loop\n";
    for (std::size_t j = k; j < k + 3; ++j) {
      double p[3];
      std::memcpy(p, corners[j].data(), sizeof p);
      char line[128];
      std::snprintf(line, sizeof line, "vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
      stl += line;
    }
    stl += "endloop\nendfacet\n";
  }
  stl += "endsolid c\n";
  Outcome outcome;
  try_variant(stl, Format::Stl, "crafted corners", outcome);  // a valid mesh (most faces are slivers, dropped)
  CHECK(outcome.meshes == 1);
}
