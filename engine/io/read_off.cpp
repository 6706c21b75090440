/// \file read_off.cpp
/// OFF (Geomview/Princeton): ASCII with optional C/N/ST prefixes (extra per-vertex values and face
/// colours are ignored), and "OFF BINARY" (big-endian int32 counts, float32 coordinates).
/// ASCII records start on a new line; one with too few values on its line (a wrapped vertex, face
/// or count line) takes the rest from the following lines, as the free-format spec allows.

#include <algorithm>
#include <exception>
#include <string>

#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh::io {

namespace {

[[noreturn]] void fail_at(std::size_t line, const std::string& what) {
  fail("OFF line " + std::to_string(line) + ": " + what);
}

/// Next line with content (comments after '#' removed); false at the end.
bool next_content_line(LineScanner& lines, std::string_view& line) {
  while (lines.next(line)) {
    std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    std::string_view probe = line, tok;
    if (next_token(probe, tok)) return true;
  }
  return false;
}

std::int64_t parse_count(std::string_view tok, std::size_t line, const char* what) {
  std::int64_t v = 0;
  if (!parse_int(tok, v) || v < 0) fail_at(line, std::string("bad ") + what + " count " + quote(tok));
  return v;
}

/// The tokens of the ASCII body: a record starts at a content line and, if it needs more values
/// than that line holds, continues with the tokens of the next content lines. What is left on the
/// line where a record completes (colours, normals, texture coordinates) is dropped by the next
/// start(). Works line by line on views of the file: no copy, no token list.
class Tokens {
 public:
  Tokens(LineScanner& lines, std::string_view rest) : lines_(lines), rest_(rest) {}
  /// Moves to the next content line, where a record starts; false at the end of the file.
  bool start() { return next_content_line(lines_, rest_); }
  /// The next token of the record, from the following content lines if its line has no more;
  /// false at the end of the file.
  bool next(std::string_view& tok) {
    while (!next_token(rest_, tok))
      if (!next_content_line(lines_, rest_)) return false;
    return true;
  }
  /// True if the rest of the current line holds a printable character (not a line of NUL padding
  /// or a DOS end-of-file mark).
  bool line_has_text() const {
    return std::any_of(rest_.begin(), rest_.end(), [](char c) {
      const auto u = static_cast<unsigned char>(c);
      return u > 0x20 && u != 0x7f;
    });
  }
  /// True if the current line has tokens left.
  bool line_has_more() const {
    std::string_view probe = rest_, tok;
    return next_token(probe, tok);
  }
  std::size_t line() const { return lines_.line_number(); }  ///< of the last token returned

 private:
  LineScanner& lines_;
  std::string_view rest_;
};

void check_counts(std::int64_t nv, std::int64_t nf, std::size_t bytes_left, std::size_t min_v,
                  std::size_t min_f, const ReadOptions& options) {
  // Each vertex and face needs some bytes: refuse absurd counts before allocating anything, and
  // before the face limit, so that a small file claiming a billion faces is malformed, not too large.
  if (static_cast<std::uint64_t>(nv) > bytes_left / min_v ||
      static_cast<std::uint64_t>(nf) > bytes_left / min_f ||
      static_cast<std::uint64_t>(nv) * min_v + static_cast<std::uint64_t>(nf) * min_f > bytes_left + 2)
    fail("OFF header claims " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
         " faces, but only " + std::to_string(bytes_left) + " bytes follow (file truncated?)");
  check_face_limit(static_cast<std::uint64_t>(nf), options, "OFF");
}

RawSoup read_off_binary(std::string_view bytes, std::size_t data_start, const ReadOptions& options) {
  ByteReader r(bytes, data_start);
  if (!r.has(12)) fail("binary OFF: truncated header (need 3 int32 counts)");
  std::int64_t nv = r.read<std::int32_t>(true), nf = r.read<std::int32_t>(true);
  r.skip(4);
  if (nv < 0 || nf < 0) fail("binary OFF: negative vertex or face count");
  check_counts(nv, nf, r.remaining(), 12, 8, options);
  RawSoup soup;
  soup.points.reserve(static_cast<std::size_t>(nv));
  for (std::int64_t i = 0; i < nv; ++i) {
    double c[3];
    for (double& v : c) v = r.read<float>(true);
    soup.points.emplace_back(c[0], c[1], c[2]);
  }
  for (std::int64_t f = 0; f < nf; ++f) {
    if (!r.has(4)) fail("binary OFF: truncated at face " + std::to_string(f) + " of " + std::to_string(nf));
    std::int64_t n = r.read<std::int32_t>(true);
    if (n < 0) fail("binary OFF: face " + std::to_string(f) + " has a negative vertex count " + std::to_string(n));
    if (!r.has(static_cast<std::uint64_t>(n) * 4 + 4))
      fail("binary OFF: face " + std::to_string(f) + " declares " + std::to_string(n) +
           " vertices but the file ends first");
    for (std::int64_t k = 0; k < n; ++k) soup.indices.push_back(r.read<std::int32_t>(true));
    std::int64_t colors = r.read<std::int32_t>(true);
    if (colors < 0 || !r.has(static_cast<std::uint64_t>(colors) * 4))
      fail("binary OFF: face " + std::to_string(f) + " has a bad colour count " + std::to_string(colors));
    r.skip(static_cast<std::size_t>(colors) * 4);
    soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
  }
  return soup;
}

/// The vertex and face records of an ASCII OFF file, from the content line after `lines` (the line
/// of the counts, or of the edge count), nv and nf of them.
RawSoup read_records(LineScanner lines, std::int64_t nv, std::int64_t nf) {
  Tokens tokens(lines, {});
  std::string_view tok;
  // The first record continued on another line: a hint for the end-of-file messages, since a value
  // missing on a line makes its record take the next line's first value and the file end early.
  std::string wrapped;
  auto ends = [&wrapped](std::string message) {
    if (!wrapped.empty()) message += " (" + wrapped + " is the first record continued on the next line)";
    return message;
  };

  RawSoup soup;
  soup.points.reserve(static_cast<std::size_t>(nv));
  soup.point_lines.reserve(static_cast<std::size_t>(nv));
  for (std::int64_t i = 0; i < nv; ++i) {
    if (!tokens.start())
      fail(ends("OFF: file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices"));
    const std::size_t ln = tokens.line();
    double c[3];
    for (int k = 0; k < 3; ++k) {
      if (!tokens.next(tok))
        fail_at(ln, "vertex " + std::to_string(i) + " has fewer than 3 coordinates (the file ends after " +
                        std::to_string(k) + ")");
      if (!parse_double(tok, c[k]))
        fail_at(tokens.line(), "bad coordinate " + quote(tok) + " of vertex " + std::to_string(i) +
                                    too_large_note(tok));
    }
    if (wrapped.empty() && tokens.line() != ln)
      wrapped = "vertex " + std::to_string(i) + " at line " + std::to_string(ln);
    soup.points.emplace_back(c[0], c[1], c[2]);
    soup.point_lines.push_back(static_cast<std::uint32_t>(ln));
  }
  soup.offsets.reserve(static_cast<std::size_t>(nf) + 1);
  soup.face_lines.reserve(static_cast<std::size_t>(nf));
  for (std::int64_t f = 0; f < nf; ++f) {
    if (!tokens.start())
      fail(ends("OFF: file ends after " + std::to_string(f) + " of " + std::to_string(nf) + " faces"));
    const std::size_t ln = tokens.line();
    std::int64_t n = 0;
    if (!tokens.next(tok) || !parse_int(tok, n) || n < 0)
      fail_at(ln, "bad vertex count " + quote(tok) + " of face " + std::to_string(f));
    for (std::int64_t k = 0; k < n; ++k) {
      std::int64_t idx = 0;
      if (!tokens.next(tok))
        fail_at(ln, "face " + std::to_string(f) + " declares " + std::to_string(n) +
                        " vertices but the file ends after " + std::to_string(k));
      if (!parse_int(tok, idx))
        fail_at(tokens.line(), "bad vertex index " + quote(tok) + " in face " + std::to_string(f));
      soup.indices.push_back(idx);
    }
    if (wrapped.empty() && tokens.line() != ln)
      wrapped = "face " + std::to_string(f) + " at line " + std::to_string(ln);
    soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
    soup.face_lines.push_back(static_cast<std::uint32_t>(ln));
  }
  // Content after the declared faces is not read, but said: a face count too small in the header
  // drops the faces past it (the mesh then has holes there), which the reader used to do silently.
  std::size_t first = 0, extra = 0;
  while (tokens.start())
    if (tokens.line_has_text() && extra++ == 0) first = tokens.line();
  if (extra > 0) {
    soup.repairs.push_back({"off_lines_after_faces_ignored", extra,
                            std::to_string(extra) + (extra == 1 ? " content line" : " content lines") + " after the " +
                                std::to_string(nf) + " faces the header declares ignored, from line " +
                                std::to_string(first) + " (is the header's face count too small?)"});
  }
  return soup;
}

}  // namespace

RawSoup read_off(std::string_view bytes, const ReadOptions& options) {
  LineScanner lines(bytes);
  std::string_view line;
  if (!next_content_line(lines, line)) fail("OFF: empty file");
  std::string_view rest = line, keyword;
  next_token(rest, keyword);
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
    fail("OFF line " + std::to_string(lines.line_number()) + ": expected the OFF keyword, found " + quote(keyword));
  std::string_view prefix = keyword.substr(0, keyword.size() - 3);
  if (prefix.find('4') != std::string_view::npos || prefix.find('n') != std::string_view::npos)
    fail("OFF: only 3D OFF is supported, not " + quote(keyword));
  std::string_view probe = rest, tok;
  if (next_token(probe, tok) && tok == "BINARY") return read_off_binary(bytes, lines.position(), options);

  // The counts: after the keyword or on the next content line, possibly split over lines.
  Tokens tokens(lines, rest);
  if (!tokens.next(tok)) fail("OFF: missing the vertex/face count line");
  const std::size_t count_line = tokens.line();
  const std::int64_t nv = parse_count(tok, count_line, "vertex");
  if (!tokens.next(tok)) fail_at(count_line, "missing face count");
  const std::int64_t nf = parse_count(tok, tokens.line(), "face");
  check_counts(nv, nf, lines.remaining(), 5, 7, options);
  // The edge count (ignored) and anything else after the face count on its line are passed over by
  // the first record. If the face count ends its line and the next content line holds one integer
  // alone, that is either the edge count of a wrapped header (the spec puts it there) or the first
  // value of a vertex wrapped one value per line: the records are read the spec's way first, and
  // the other way if that fails (both failing, the first error stands). A header without the edge
  // count ("8 6") followed by whole vertex lines reads as it always did.
  if (!tokens.line_has_more()) {
    LineScanner ahead = lines;
    std::string_view next, first, extra;
    std::int64_t edges = 0;
    if (next_content_line(ahead, next) && next_token(next, first) && !next_token(next, extra) &&
        parse_int(first, edges)) {
      try {
        return read_records(ahead, nv, nf);
      } catch (const MeshError&) {
        const std::exception_ptr spec_error = std::current_exception();
        try {
          return read_records(lines, nv, nf);
        } catch (const MeshError&) {
          std::rethrow_exception(spec_error);
        }
      }
    }
  }
  return read_records(lines, nv, nf);
}

}  // namespace remesh::io
