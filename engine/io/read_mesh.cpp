/// \file read_mesh.cpp
/// read_mesh / read_mesh_file: choose the format, run its reader, validate and repair.

#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh {

LoadedMesh read_mesh(std::string_view bytes, const ReadOptions& options) {
  if (bytes.empty()) throw MeshError("empty input: no bytes to read");
  std::optional<Format> format = options.format ? options.format : detect_format(bytes);
  // .gltf and .glb are often confused by clients: trust the content when it is clearly one of them.
  if (format == Format::Gltf || format == Format::Glb) {
    const std::optional<Format> sniffed = detect_format(bytes);
    if (sniffed == Format::Gltf || sniffed == Format::Glb) format = sniffed;
  }
  if (!format) throw MeshError("unrecognised mesh format (supported: OBJ, OFF, PLY, STL, glTF, GLB)");
  // A UTF-8 byte order mark before a text header (editors on Windows write one): detect_format
  // passes over it, and so do the readers now. (The OBJ reader took "\xEF\xBB\xBFv" for an unknown
  // line and dropped the first vertex; PLY and ASCII STL refused the file.) STL sees to its own:
  // a binary STL's 80-byte header may start with any bytes.
  if (bytes.starts_with("\xEF\xBB\xBF") && *format != Format::Stl && *format != Format::Glb) bytes.remove_prefix(3);
  io::RawSoup soup;
  try {
    switch (*format) {
      case Format::Obj: soup = io::read_obj(bytes, options); break;
      case Format::Off: soup = io::read_off(bytes, options); break;
      case Format::Ply: soup = io::read_ply(bytes, options); break;
      case Format::Stl: soup = io::read_stl(bytes, options); break;
      case Format::Gltf: soup = io::read_gltf(bytes, false, options); break;
      case Format::Glb: soup = io::read_gltf(bytes, true, options); break;
      case Format::Xyz: throw MeshError("unsupported input format xyz (a point list has no faces)");
      case Format::Lammps: throw MeshError("unsupported input format lammps (atoms and bonds, no faces)");
    }
  } catch (const MeshError& e) {
    // Given as one format (a name, a format parameter, a content type) and refused by its reader,
    // while the content is clearly another: say so (an OFF file uploaded as .stl got only the STL
    // reader's complaint).
    const std::optional<Format> sniffed = options.format ? detect_format(bytes) : std::nullopt;
    if (!sniffed || sniffed == format) throw;
    throw MeshError(std::string(e.what()) + "; it was read as " + std::string(format_name(*format)) +
                    " (the format it was given as), but its content looks like " + std::string(format_name(*sniffed)));
  }
  // The OBJ reader passes over lines it does not know: a PLY or OFF file under an .obj name reads
  // as empty. Say what the content looks like instead of "no vertices and no faces".
  if (soup.points.empty() && soup.face_count() == 0 && options.format) {
    const std::optional<Format> sniffed = detect_format(bytes);
    if (sniffed && sniffed != format)
      throw MeshError("read as " + std::string(format_name(*format)) + " (the format it was given as) it holds " +
                      "no vertices and no faces, but its content looks like " + std::string(format_name(*sniffed)));
    // Nor is a file with a NUL byte OBJ text: an image or another binary file under an .obj name.
    if (!sniffed && *format == Format::Obj && bytes.find('\0') != std::string_view::npos)
      throw MeshError("read as obj (the format it was given as) it holds no vertices and no faces: its content "
                      "is binary data, not OBJ text nor any mesh format this reader knows");
  }
  LoadedMesh out{TriMesh(), *format, std::move(soup.repairs)};
  out.mesh = io::build_mesh(std::move(soup), options, out.repairs);
  return out;
}

LoadedMesh read_mesh_file(const std::string& path, ReadOptions options) {
  // A device or a pipe may never end (remesh info /dev/zero read forever): regular files only.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
    throw MeshError("'" + path + "' is not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshError("cannot open '" + path + "'");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw MeshError("cannot read '" + path + "'");
  const std::string bytes = std::move(buffer).str();
  if (!options.format) options.format = parse_format(path);
  if (bytes.empty()) throw MeshError("'" + path + "' is empty");
  return read_mesh(bytes, options);
}

}  // namespace remesh
