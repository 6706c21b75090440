/// \file write_text.cpp
/// Text writers: OBJ, OFF (ASCII) and XYZ. Coordinates use the shortest decimal form that reads
/// back as the same double, so positions round-trip exactly.

#include <charconv>

#include "io/writers.h"

namespace remesh::io {

void append_number(std::string& out, double v) {
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

namespace {

void append_uint(std::string& out, std::uint64_t v) {
  char buf[24];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, end);
  (void)ec;
}

void append_point(std::string& out, const Vec3& p) {
  for (int k = 0; k < 3; ++k) {
    out += ' ';
    append_number(out, p[k]);
  }
  out += '\n';
}

}  // namespace

std::string write_obj(const PolygonSoup& soup) {
  std::string out = "# written by remeshd\n";
  out.reserve(soup.points.size() * 40 + soup.indices.size() * 8);
  for (const Vec3& p : soup.points) {
    out += 'v';
    append_point(out, p);
  }
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    out += 'f';
    for (std::uint32_t k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) {
      out += ' ';
      append_uint(out, std::uint64_t{soup.indices[k]} + 1);
    }
    out += '\n';
  }
  return out;
}

std::string write_off(const PolygonSoup& soup) {
  std::string out = "OFF\n";
  const std::size_t faces = soup.offsets.size() - 1;
  append_uint(out, soup.points.size());
  out += ' ';
  append_uint(out, faces);
  out += " 0\n";
  for (const Vec3& p : soup.points) {
    std::string line;
    append_point(line, p);
    out.append(line, 1);  // no leading space
  }
  for (std::size_t f = 0; f < faces; ++f) {
    append_uint(out, soup.offsets[f + 1] - soup.offsets[f]);
    for (std::uint32_t k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) {
      out += ' ';
      append_uint(out, soup.indices[k]);
    }
    out += '\n';
  }
  return out;
}

std::string write_xyz(const PolygonSoup& soup) {
  std::string out;
  append_uint(out, soup.points.size());
  out += "\nwritten by remeshd: one carbon atom per point\n";
  for (const Vec3& p : soup.points) {
    out += 'C';
    append_point(out, p);
  }
  return out;
}

}  // namespace remesh::io
