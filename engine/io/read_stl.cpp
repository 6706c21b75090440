/// \file read_stl.cpp
/// STL, ASCII and binary. STL has no shared vertices: corners are welded by exact position here
/// (part of reading the format, not a repair). Binary is recognised by its size (84 + 50 n bytes),
/// even when its header starts with "solid".

#include <cstring>
#include <string>
#include <unordered_map>

#include "io/parse_util.h"
#include "io/point_hash.h"
#include "io/soup.h"

namespace remesh::io {

namespace {

/// Welds corners by exact position (-0 and +0 are one position; NaNs are kept apart so the
/// validator can name them).
class Welder {
 public:
  explicit Welder(RawSoup& soup) : soup_(soup) {}
  std::int64_t add(const Vec3& p, std::uint32_t line) {
    Key k{};
    for (int i = 0; i < 3; ++i) {
      double v = p[i] + 0.0;
      std::memcpy(&k.bits[i], &v, 8);
    }
    bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    if (finite) {
      auto [it, inserted] = map_.try_emplace(k, soup_.points.size());
      if (!inserted) return static_cast<std::int64_t>(it->second);
    }
    soup_.points.push_back(p);
    if (line > 0) soup_.point_lines.push_back(line);
    return static_cast<std::int64_t>(soup_.points.size() - 1);
  }

 private:
  struct Key {
    std::uint64_t bits[3];
    bool operator==(const Key& o) const { return std::memcmp(bits, o.bits, sizeof bits) == 0; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const { return static_cast<std::size_t>(point_hash(k.bits)); }
  };
  RawSoup& soup_;
  std::unordered_map<Key, std::size_t, Hash> map_;
};

RawSoup read_binary_stl(std::string_view bytes, const ReadOptions& options) {
  if (bytes.size() < 84) fail("binary STL: file has " + std::to_string(bytes.size()) + " bytes, less than the 84-byte header");
  ByteReader r(bytes, 80);
  const std::uint64_t n = r.read<std::uint32_t>(false);
  // The size first, the limit after (both before reserving): text read as a binary STL (an OFF
  // under an .stl name) gives a count in the hundreds of millions, and "more faces than the limit"
  // (HTTP 413) would call a malformed 42 KB file too large.
  if (84 + 50 * n > bytes.size())
    fail("binary STL: header says " + std::to_string(n) + " triangles (" + std::to_string(84 + 50 * n) +
         " bytes) but the file has " + std::to_string(bytes.size()) + " bytes (truncated?)");
  check_face_limit(n, options, "STL");
  RawSoup soup;
  soup.points.reserve(n);
  soup.indices.reserve(3 * n);
  soup.offsets.reserve(n + 1);
  Welder welder(soup);
  for (std::uint64_t t = 0; t < n; ++t) {
    r.skip(12);  // normal
    for (int c = 0; c < 3; ++c) {
      double x = r.read<float>(false), y = r.read<float>(false), z = r.read<float>(false);
      soup.indices.push_back(welder.add(Vec3(x, y, z), 0));
    }
    r.skip(2);
    soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
  }
  return soup;
}

[[noreturn]] void fail_at(std::size_t line, const std::string& what) {
  fail("ASCII STL line " + std::to_string(line) + ": " + what);
}

/// Keywords in any case: the format's spec writes them in lower case, but some exporters write
/// "SOLID", "FACET NORMAL", ... (such a file was taken for a binary one of 1.3 billion triangles).
RawSoup read_ascii_stl(std::string_view bytes, const ReadOptions& options) {
  RawSoup soup;
  Welder welder(soup);
  LineScanner lines(bytes);
  std::string_view line, tok;
  bool in_loop = false, ended = false;
  std::size_t corners = 0;
  while (lines.next(line)) {
    std::string_view rest = line;
    if (!next_token(rest, tok)) continue;
    const std::size_t ln = lines.line_number();
    if (is_word_in_any_case(tok, "outer")) {
      if (in_loop) fail_at(ln, "'outer loop' inside another loop");
      in_loop = true;
      corners = 0;
      check_face_limit(soup.face_count() + 1, options, "STL");
      soup.face_lines.push_back(static_cast<std::uint32_t>(ln));
    } else if (is_word_in_any_case(tok, "vertex")) {
      if (!in_loop) fail_at(ln, "'vertex' outside 'outer loop'");
      double c[3];
      for (double& v : c) {
        if (!next_token(rest, tok)) fail_at(ln, "vertex has fewer than 3 coordinates");
        if (!parse_double(tok, v)) fail_at(ln, "bad vertex coordinate " + quote(tok) + too_large_note(tok));
      }
      soup.indices.push_back(welder.add(Vec3(c[0], c[1], c[2]), static_cast<std::uint32_t>(ln)));
      ++corners;
    } else if (is_word_in_any_case(tok, "endloop")) {
      if (!in_loop) fail_at(ln, "'endloop' without 'outer loop'");
      in_loop = false;
      soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
    } else if (is_word_in_any_case(tok, "endsolid")) {
      ended = true;
    } else if (!is_word_in_any_case(tok, "solid") && !is_word_in_any_case(tok, "facet") &&
               !is_word_in_any_case(tok, "endfacet")) {
      fail_at(ln, "unexpected keyword " + quote(tok));
    }
  }
  if (in_loop) fail("ASCII STL: file ends inside a facet (truncated?)");
  if (!ended) fail("ASCII STL: no 'endsolid' line (truncated?)");
  (void)corners;
  return soup;
}

}  // namespace

RawSoup read_stl(std::string_view bytes, const ReadOptions& options) {
  if (bytes.size() >= 84) {
    ByteReader r(bytes, 80);
    const std::uint64_t n = r.read<std::uint32_t>(false);
    if (84 + 50 * n == bytes.size()) return read_binary_stl(bytes, options);
  }
  std::string_view text = bytes;
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // a UTF-8 byte order mark
  while (!text.empty() && (is_space(text[0]) || text[0] == '\n')) text.remove_prefix(1);
  // ASCII STL holds no NUL byte; a binary one whose header starts with "solid" (many exporters
  // write one) almost always does, in its counts and coordinates: a truncated binary file is then
  // reported as binary, with its size, not as ASCII without 'endsolid'.
  if (is_word_in_any_case(text.substr(0, 5), "solid") && bytes.find('\0') == std::string_view::npos)
    return read_ascii_stl(text, options);
  return read_binary_stl(bytes, options);
}

}  // namespace remesh::io
