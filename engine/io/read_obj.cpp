/// \file read_obj.cpp
/// Wavefront OBJ: `v` and `f` lines (v, v/vt, v//vn, v/vt/vn, negative indices); everything else
/// (vt, vn, g, o, s, usemtl, mtllib, l) is skipped, as is a comment from '#' on any line. CRLF is
/// fine.

#include <string>

#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh::io {

namespace {

[[noreturn]] void fail_at(std::size_t line, const std::string& what) {
  fail("OBJ line " + std::to_string(line) + ": " + what);
}

void parse_vertex(std::string_view rest, std::size_t line, RawSoup& soup) {
  double c[3];
  std::string_view tok;
  for (double& v : c) {
    // No index: OBJ counts vertices from 1, the other messages from 0; the line says which.
    if (!next_token(rest, tok)) fail_at(line, "a vertex with fewer than 3 coordinates");
    if (!parse_double(tok, v)) fail_at(line, "bad vertex coordinate " + quote(tok) + too_large_note(tok));
  }
  soup.points.emplace_back(c[0], c[1], c[2]);
  soup.point_lines.push_back(static_cast<std::uint32_t>(line));
}

void parse_face(std::string_view rest, std::size_t line, RawSoup& soup) {
  std::string_view tok;
  const auto defined = static_cast<std::int64_t>(soup.points.size());
  while (next_token(rest, tok)) {
    std::string_view index = tok.substr(0, tok.find('/'));
    std::int64_t i = 0;
    if (!parse_int(index, i)) fail_at(line, "bad face index " + quote(tok));
    if (i == 0) fail_at(line, "face index 0 is invalid (OBJ indices start at 1)");
    if (i < 0) {
      if (i < -defined)  // not -i > defined: -i overflows for the smallest int64
        fail_at(line, "relative face index " + std::to_string(i) + " reaches before the first vertex (" +
                          std::to_string(defined) + " defined so far)");
      soup.indices.push_back(defined + i);
    } else {
      soup.indices.push_back(i - 1);
    }
  }
  if (soup.indices.size() > UINT32_MAX) fail_at(line, "too many face indices");
  soup.offsets.push_back(static_cast<std::uint32_t>(soup.indices.size()));
  soup.face_lines.push_back(static_cast<std::uint32_t>(line));
}

}  // namespace

RawSoup read_obj(std::string_view bytes, const ReadOptions& options) {
  RawSoup soup;
  soup.index_base = 1;
  LineScanner lines(bytes);
  std::string_view line;
  while (lines.next(line)) {
    std::string_view rest = line.substr(0, line.find('#')), tok;  // a comment may end any line
    if (!next_token(rest, tok)) continue;
    if (tok == "v") {
      parse_vertex(rest, lines.line_number(), soup);
    } else if (tok == "f" || tok == "fo") {
      check_face_limit(soup.face_count() + 1, options, "OBJ");
      parse_face(rest, lines.line_number(), soup);
    }
  }
  return soup;
}

}  // namespace remesh::io
