#pragma once
/// \file writers.h
/// Internal: one serialiser per output format (write_mesh() dispatches).

#include <string>

#include "io/mesh_io.h"

namespace remesh::io {

std::string write_obj(const PolygonSoup& soup);  ///< shortest round-trip decimal coordinates
std::string write_off(const PolygonSoup& soup);  ///< ASCII OFF, polygons kept
std::string write_xyz(const PolygonSoup& soup);  ///< "C x y z" per point
std::string write_lammps(const PolygonSoup& soup);  ///< LAMMPS data: atoms, bonds along face edges
std::string write_ply(const PolygonSoup& soup);  ///< binary little endian, double coordinates
std::string write_stl(const PolygonSoup& soup);  ///< binary, fan-triangulated, float32
std::string write_glb(const PolygonSoup& soup);  ///< triangles (+ LINES of polygon edges)
std::string write_gltf(const PolygonSoup& soup);  ///< the same document as text, its buffer a base64 data: URI

/// Appends the shortest decimal text that reads back as exactly v.
void append_number(std::string& out, double v);

/// Throws std::range_error, naming `format` and the first such point, if a coordinate does not
/// round to a finite float32 (magnitude about 3.4e38 or more): STL, GLB and glTF store float32.
void check_float32(const PolygonSoup& soup, const char* format);

/// Throws std::range_error, naming `format`, if `bytes` do not fit the 32-bit lengths and offsets
/// of GLB and glTF (more than 4 GiB - 1): past that the file would be silently wrong.
void check_32bit_length(std::size_t bytes, const char* format);

/// Fan triangles of every face: (f0, fi, fi+1).
template <class F>
void for_each_fan_triangle(const PolygonSoup& soup, F&& f) {
  for (std::size_t face = 0; face + 1 < soup.offsets.size(); ++face) {
    const std::uint32_t b = soup.offsets[face], e = soup.offsets[face + 1];
    for (std::uint32_t k = b + 1; k + 1 < e; ++k) f(soup.indices[b], soup.indices[k], soup.indices[k + 1]);
  }
}

}  // namespace remesh::io
