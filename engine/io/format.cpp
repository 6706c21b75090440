/// \file format.cpp
/// Format names, extensions, MIME types and content sniffing.

#include <algorithm>
#include <cctype>
#include <string>

#include "io/mesh_io.h"
#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh {

std::string_view format_name(Format f) {
  switch (f) {
    case Format::Obj: return "obj";
    case Format::Off: return "off";
    case Format::Ply: return "ply";
    case Format::Stl: return "stl";
    case Format::Gltf: return "gltf";
    case Format::Glb: return "glb";
    case Format::Xyz: return "xyz";
    case Format::Lammps: return "lammps";
  }
  return "unknown";
}

std::string_view mime_type(Format f) {
  switch (f) {
    case Format::Obj: return "model/obj";
    case Format::Off: return "model/x-off";
    case Format::Ply: return "model/x-ply";
    case Format::Stl: return "model/stl";
    case Format::Gltf: return "model/gltf+json";
    case Format::Glb: return "model/gltf-binary";
    case Format::Xyz: return "chemical/x-xyz";
    case Format::Lammps: return "text/plain; charset=utf-8";
  }
  return "application/octet-stream";
}

std::optional<Format> parse_format(std::string_view name_or_path) {
  std::size_t dot = name_or_path.rfind('.');
  std::size_t slash = name_or_path.find_last_of("/\\");
  std::string_view ext = name_or_path;
  if (dot != std::string_view::npos && (slash == std::string_view::npos || dot > slash))
    ext = name_or_path.substr(dot + 1);
  if (ext.size() > 8) return std::nullopt;
  std::string lower(ext);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (Format f : {Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Gltf, Format::Glb,
                   Format::Xyz, Format::Lammps})
    if (lower == format_name(f)) return f;
  if (lower == "lmp" || lower == "data") return Format::Lammps;
  return std::nullopt;
}

namespace {

bool starts_with_word(std::string_view s, std::string_view word) {
  if (s.substr(0, word.size()) != word) return false;
  return s.size() == word.size() || io::is_space(s[word.size()]) || s[word.size()] == '\n';
}

bool looks_like_obj(std::string_view bytes) {
  io::LineScanner lines(bytes.substr(0, 1 << 16));
  std::string_view line;
  int checked = 0;
  while (lines.next(line) && checked < 200) {
    std::string_view rest = line, tok;
    if (!io::next_token(rest, tok)) continue;
    ++checked;
    if (tok == "v" || tok == "vt" || tok == "vn" || tok == "f" || tok == "o" || tok == "g" ||
        tok == "mtllib" || tok == "usemtl")
      return true;
    if (tok[0] != '#' && tok != "s") return false;
  }
  return false;
}

}  // namespace

std::optional<Format> detect_format(std::string_view bytes) {
  if (bytes.size() >= 4 && bytes.substr(0, 4) == "glTF") return Format::Glb;
  std::string_view text = bytes;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  while (!text.empty() && (io::is_space(text[0]) || text[0] == '\n')) text.remove_prefix(1);
  if (!text.empty() && text[0] == '{') return Format::Gltf;
  if (starts_with_word(text, "ply")) return Format::Ply;
  std::string_view first = text, tok;
  if (io::next_token(first, tok)) {
    std::size_t nl = tok.find('\n');
    if (nl != std::string_view::npos) tok = tok.substr(0, nl);
    if (tok.size() >= 3 && tok.size() <= 8 && tok.substr(tok.size() - 3) == "OFF") return Format::Off;
  }
  if (bytes.size() >= 84) {
    io::ByteReader r(bytes, 80);
    std::uint64_t n = r.read<std::uint32_t>(false);
    if (84 + 50 * n == bytes.size()) return Format::Stl;
  }
  // ASCII STL's first word in any case ("SOLID" from some exporters; read_stl.cpp reads it so).
  if (io::is_word_in_any_case(text.substr(0, 5), "solid") &&
      (text.size() == 5 || io::is_space(text[5]) || text[5] == '\n'))
    return Format::Stl;
  if (looks_like_obj(text)) return Format::Obj;
  return std::nullopt;
}

namespace io {

std::string RawSoup::point_where(std::size_t i) const {
  if (i < point_lines.size() && point_lines[i] > 0) return " (line " + std::to_string(point_lines[i]) + ")";
  return "";
}

std::string RawSoup::face_where(std::size_t f) const {
  if (f < face_lines.size() && face_lines[f] > 0) return " (line " + std::to_string(face_lines[f]) + ")";
  return "";
}

void check_face_limit(std::uint64_t faces, const ReadOptions& options, const char* what) {
  if (options.max_faces > 0 && faces > options.max_faces)
    throw LimitError(std::string(what) + " has more than " + std::to_string(options.max_faces) +
                     " faces (the limit); found at least " + std::to_string(faces));
}

}  // namespace io
}  // namespace remesh
