#pragma once
/// \file soup.h
/// Internal: the polygon soup a reader produces before validation and repair (build_mesh.cpp).

#include <cstdint>
#include <string>
#include <vector>

#include "io/mesh_io.h"

namespace remesh::io {

/// What a reader found: points and polygons, with where each came from for error messages.
/// Indices are 0-based and NOT yet range-checked (build_soup_mesh does that).
struct RawSoup {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> point_lines;  ///< source line of each point (text formats), else empty
  std::vector<std::int64_t> indices;       ///< may be out of range; checked later
  std::vector<std::uint32_t> offsets{0};   ///< face f = indices[offsets[f] .. offsets[f+1])
  std::vector<std::uint32_t> face_lines;   ///< source line of each face (text formats), else empty
  std::vector<Repair> repairs;             ///< repairs a reader made itself (rare)
  /// How the file counts its vertices (1 for OBJ): an index out of range is named as written.
  int index_base = 0;

  std::size_t face_count() const { return offsets.size() - 1; }
  /// " (line N)" for point i if known, else "".
  std::string point_where(std::size_t i) const;
  /// " (line N)" for face f if known, else "".
  std::string face_where(std::size_t f) const;
};

/// Per-format readers. Each throws MeshError naming the problem and where, LimitError when the
/// face count exceeds options.max_faces (checked before allocating, once the declared counts are
/// known to fit the file's size: counts that cannot are a MeshError).
RawSoup read_obj(std::string_view bytes, const ReadOptions& options);
RawSoup read_off(std::string_view bytes, const ReadOptions& options);
RawSoup read_ply(std::string_view bytes, const ReadOptions& options);
RawSoup read_stl(std::string_view bytes, const ReadOptions& options);
RawSoup read_gltf(std::string_view bytes, bool binary, const ReadOptions& options);

/// Validates and repairs a soup into a 2-manifold, consistently oriented TriMesh (see mesh_io.h).
/// Appends repairs to `repairs`. Throws MeshError / LimitError.
TriMesh build_mesh(RawSoup soup, const ReadOptions& options, std::vector<Repair>& repairs);

/// Throws LimitError if `faces` exceeds options.max_faces (when set). `what` names the source.
void check_face_limit(std::uint64_t faces, const ReadOptions& options, const char* what);

}  // namespace remesh::io
