// Truncated and byte-flipped files in every input format: an error (MeshError / LimitError) or a
// valid mesh, never a crash, a hang or another exception type. Also built with ASan + UBSan.
#include <catch2/catch.hpp>

#include <random>

#include "io/mesh_io.h"
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
    const std::size_t n = file.bytes.size();
    // Truncations: every length near both ends, then ~150 spread over the file.
    for (std::size_t len = 0; len < n; len += (len < 64 || len + 64 > n) ? 1 : std::max<std::size_t>(1, n / 150)) {
      const std::string cut = file.bytes.substr(0, len);
      try_variant(cut, len % 2 ? std::optional<Format>(file.format) : std::nullopt,
                  file.name + " truncated to " + std::to_string(len), outcome);
    }
    // Byte flips: 1 to 4 random bytes set to random values (half of them to "interesting" ones).
    const unsigned char interesting[] = {0, 0xff, 0x7f, 0x80, '0', '9', '-', '.', 'e', ' ', '\n', '/', '#', '"', '{'};
    for (int variant = 0; variant < 300; ++variant) {
      std::string bad = file.bytes;
      const int flips = 1 + variant % 4;
      std::string where;
      for (int k = 0; k < flips; ++k) {
        const std::size_t at = std::uniform_int_distribution<std::size_t>(0, n - 1)(rng);
        const unsigned v = rng();
        bad[at] = static_cast<char>(v % 2 ? interesting[(v >> 1) % sizeof interesting] : (v >> 8) & 0xff);
        where += ' ';
        where += std::to_string(at);
      }
      try_variant(bad, variant % 3 ? std::optional<Format>(file.format) : std::nullopt,
                  file.name + " with bytes changed at" + where, outcome, variant % 4 == 1);
    }
    CHECK(outcome.errors > 0);
    CHECK(outcome.meshes > 1);
  }
}
