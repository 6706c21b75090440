// BodyDecoder: coded request bodies undone piece by piece, and a stream that did not end told apart.
#include <catch2/catch.hpp>

#include <brotli/encode.h>
#include <zlib.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "body_decoder.h"
#include "io/mesh_io.h"
#include "support/mesh_generators.h"

using remeshd::BodyDecoder;

namespace {

std::string sphere_obj_text(int subdiv) { return remesh::write_mesh(remesh::test::make_icosphere(subdiv), remesh::Format::Obj); }

/// zlib's deflate with window bits `wbits` (31: gzip, 15: zlib); `flush_at`: after that many input
/// bytes a sync flush, whose end offset in the output goes to *flushed.
std::string zlib_code(const std::string& in, int wbits, std::size_t flush_at = 0, std::size_t* flushed = nullptr) {
  z_stream z{};
  REQUIRE(deflateInit2(&z, 6, Z_DEFLATED, wbits, 8, Z_DEFAULT_STRATEGY) == Z_OK);
  std::string out;
  auto run = [&](const char* data, std::size_t n, int flush) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
    z.avail_in = static_cast<uInt>(n);
    int r;
    do {
      char buffer[4096];
      z.next_out = reinterpret_cast<Bytef*>(buffer);
      z.avail_out = sizeof buffer;
      r = deflate(&z, flush);
      out.append(buffer, sizeof buffer - z.avail_out);
    } while (z.avail_out == 0 || (flush == Z_FINISH && r != Z_STREAM_END));
  };
  if (flush_at > 0) {
    run(in.data(), flush_at, Z_SYNC_FLUSH);
    if (flushed) *flushed = out.size();
    run(in.data() + flush_at, in.size() - flush_at, Z_FINISH);
  } else {
    run(in.data(), in.size(), Z_FINISH);
  }
  deflateEnd(&z);
  return out;
}

std::string brotli_code(const std::string& in) {
  std::string out(BrotliEncoderMaxCompressedSize(in.size()), '\0');
  std::size_t size = out.size();
  REQUIRE(BrotliEncoderCompress(5, BROTLI_DEFAULT_WINDOW, BROTLI_MODE_TEXT, in.size(),
                                reinterpret_cast<const std::uint8_t*>(in.data()), &size,
                                reinterpret_cast<std::uint8_t*>(out.data())) == BROTLI_TRUE);
  out.resize(size);
  return out;
}

struct Decoded {
  bool fed = true;  ///< every feed succeeded
  bool complete = false;
  std::string text;
};

/// Feeds `coded` in pieces of 1 to max_piece bytes (pseudo-random, seeded).
Decoded decode(const std::string& coding, const std::string& coded, std::size_t max_piece, unsigned seed) {
  BodyDecoder decoder(coding);
  Decoded d;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::size_t> piece(1, max_piece);
  for (std::size_t at = 0; at < coded.size() && d.fed;) {
    const std::size_t n = std::min(piece(rng), coded.size() - at);
    d.fed = decoder.feed(coded.data() + at, n, [&](const char* p, std::size_t m) {
      d.text.append(p, m);
      return true;
    });
    at += n;
  }
  d.complete = decoder.complete();
  return d;
}

std::string coded_as(const std::string& coding, const std::string& text) {
  return coding == "gzip" ? zlib_code(text, 31) : coding == "deflate" ? zlib_code(text, 15) : brotli_code(text);
}

}  // namespace

TEST_CASE("BodyDecoder: gzip, deflate and br, fed in pieces of any size, give the body back whole",
          "[server][uploads]") {
  // A mesh as the service receives it: an OBJ of 20 480 faces, about 1 MB.
  const std::string obj = sphere_obj_text(5);
  REQUIRE(obj.size() > 500000);
  for (const std::string coding : {"gzip", "deflate", "br"}) {
    CAPTURE(coding);
    const std::string coded = coded_as(coding, obj);
    REQUIRE(coded.size() < obj.size() / 2);
    for (std::size_t max_piece : {std::size_t(1), std::size_t(7), std::size_t(4096), std::size_t(1) << 20}) {
      CAPTURE(max_piece);
      const Decoded d = decode(coding, coded, max_piece, static_cast<unsigned>(max_piece));
      CHECK(d.fed);
      CHECK(d.complete);
      CHECK(d.text == obj);
    }
  }
}

TEST_CASE("BodyDecoder: a coded body cut off is not complete, bytes after its end are refused", "[server][uploads]") {
  const std::string obj = sphere_obj_text(3);
  for (const std::string coding : {"gzip", "deflate", "br"}) {
    CAPTURE(coding);
    const std::string coded = coded_as(coding, obj);
    // Cut anywhere: not complete (or not valid), and never more than the body.
    for (std::size_t cut : {std::size_t(1), std::size_t(10), coded.size() / 3, coded.size() / 2, coded.size() - 1}) {
      CAPTURE(cut);
      const Decoded d = decode(coding, coded.substr(0, cut), 4096, 1);
      CHECK_FALSE((d.fed && d.complete));
      CHECK(obj.compare(0, d.text.size(), d.text) == 0);
    }
    const Decoded trailing = decode(coding, coded + "xyz", 4096, 2);
    CHECK_FALSE(trailing.fed);
  }
  // Cut at a flush point: every byte decoded so far is valid, and a body that ends there was what
  // httplib took for a whole mesh. Not complete.
  for (int wbits : {31, 15}) {
    CAPTURE(wbits);
    std::size_t flushed = 0;
    const std::string coded = zlib_code(obj, wbits, obj.size() / 2, &flushed);
    REQUIRE(flushed > 0);
    REQUIRE(flushed < coded.size());
    const Decoded d = decode(wbits == 31 ? "gzip" : "deflate", coded.substr(0, flushed), 4096, 3);
    CHECK(d.fed);
    CHECK(d.text == obj.substr(0, obj.size() / 2));
    CHECK_FALSE(d.complete);
  }
}

TEST_CASE("BodyDecoder: gzip members one after another, a sink that stops, unknown codings", "[server][uploads]") {
  const std::string a = "v 0 0 0\nv 1 0 0\n", b = "v 0 1 0\nf 1 2 3\n";
  const Decoded two = decode("gzip", zlib_code(a, 31) + zlib_code(b, 31), 5, 4);
  CHECK(two.fed);
  CHECK(two.complete);
  CHECK(two.text == a + b);
  // Zeros after a member pad it (GNU gzip takes them); anything else after the end is refused.
  const Decoded padded = decode("gzip", zlib_code(a, 31) + std::string(512, '\0'), 64, 6);
  CHECK(padded.fed);
  CHECK(padded.complete);
  CHECK(padded.text == a);
  const Decoded garbage = decode("gzip", zlib_code(a, 31) + std::string(8, '\0') + "xyz", 64, 7);
  CHECK_FALSE((garbage.fed && garbage.complete));
  // One zlib stream after another is not deflate.
  CHECK_FALSE(decode("deflate", zlib_code(a, 15) + zlib_code(b, 15), 5, 5).fed);

  const std::string obj = sphere_obj_text(3);
  for (const std::string coding : {"gzip", "deflate", "br"}) {
    CAPTURE(coding);
    const std::string coded = coded_as(coding, obj);
    BodyDecoder decoder(coding);
    std::size_t calls = 0;
    CHECK_FALSE(decoder.feed(coded.data(), coded.size(), [&](const char*, std::size_t) { return ++calls < 2; }));
    CHECK(calls == 2);
  }
  CHECK_THROWS_AS(BodyDecoder("zstd"), std::invalid_argument);
  CHECK_THROWS_AS(BodyDecoder("GZIP"), std::invalid_argument);  // the server names codings in lower case
}
