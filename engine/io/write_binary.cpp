/// \file write_binary.cpp
/// Binary writers: PLY (little endian, double coordinates, polygon faces) and STL (float32,
/// fan-triangulated, normals computed).

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "io/parse_util.h"
#include "io/writers.h"

namespace remesh::io {

void check_float32(const PolygonSoup& soup, const char* format) {
  // Below this, a double rounds to at most FLT_MAX; from it (ties to even) to infinity.
  constexpr double rounds_to_inf = 0x1.ffffffp+127;
  for (std::size_t i = 0; i < soup.points.size(); ++i) {
    const Vec3& p = soup.points[i];
    if (std::abs(p[0]) < rounds_to_inf && std::abs(p[1]) < rounds_to_inf && std::abs(p[2]) < rounds_to_inf)
      continue;
    std::string at = "(";
    for (int k = 0; k < 3; ++k) {
      append_number(at, p[k]);
      at += k < 2 ? ", " : ")";
    }
    throw std::range_error(std::string(format) + " cannot hold point " + std::to_string(i) + " " + at +
                           ": it stores coordinates as float32, at most about 3.4e38 in magnitude");
  }
}

std::string write_ply(const PolygonSoup& soup) {
  const std::size_t faces = soup.offsets.size() - 1;
  std::uint32_t largest = 0;
  for (std::size_t f = 0; f < faces; ++f) largest = std::max(largest, soup.offsets[f + 1] - soup.offsets[f]);
  const bool wide = largest > 255;  // a uchar count cannot hold it
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by remeshd\nelement vertex " +
                    std::to_string(soup.points.size()) +
                    "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
                    std::to_string(faces) + "\nproperty list " + (wide ? "uint" : "uchar") +
                    " uint vertex_indices\nend_header\n";
  out.reserve(out.size() + soup.points.size() * 24 + faces + soup.indices.size() * 4);
  for (const Vec3& p : soup.points)
    for (int k = 0; k < 3; ++k) put_le<double>(out, p[k]);
  for (std::size_t f = 0; f < faces; ++f) {
    const std::uint32_t n = soup.offsets[f + 1] - soup.offsets[f];
    if (wide) put_le<std::uint32_t>(out, n);
    else put_le<std::uint8_t>(out, static_cast<std::uint8_t>(n));
    for (std::uint32_t k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) put_le<std::uint32_t>(out, soup.indices[k]);
  }
  return out;
}

std::string write_stl(const PolygonSoup& soup) {
  check_float32(soup, "STL");
  std::uint32_t count = 0;
  for_each_fan_triangle(soup, [&](std::uint32_t, std::uint32_t, std::uint32_t) { ++count; });
  std::string out(80, ' ');
  const char title[] = "binary STL written by remeshd";  // must not start with "solid"
  std::memcpy(out.data(), title, sizeof title - 1);
  put_le<std::uint32_t>(out, count);
  out.reserve(84 + 50 * std::size_t{count});
  for_each_fan_triangle(soup, [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const Vec3 &pa = soup.points[a], &pb = soup.points[b], &pc = soup.points[c];
    Vec3 n = OpenMesh::cross(pb - pa, pc - pa);
    const double len = n.norm();
    if (len > 0) n /= len;
    for (const Vec3* p : {static_cast<const Vec3*>(&n), &pa, &pb, &pc})
      for (int k = 0; k < 3; ++k) put_le<float>(out, static_cast<float>((*p)[k]));
    put_le<std::uint16_t>(out, 0);
  });
  return out;
}

}  // namespace remesh::io
