/// \file write_text.cpp
/// Text writers: OBJ, OFF (ASCII), XYZ and LAMMPS data. Coordinates use the shortest decimal form
/// that reads back as the same double, so positions round-trip exactly.

#include <algorithm>
#include <charconv>
#include <utility>
#include <vector>

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

std::string write_lammps(const PolygonSoup& soup) {
  // Bonds: every edge of the faces once, as (lower index, higher index), in that order.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> bonds;
  bonds.reserve(soup.indices.size());
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    const std::uint32_t b = soup.offsets[f], e = soup.offsets[f + 1];
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t u = soup.indices[k], v = soup.indices[k + 1 < e ? k + 1 : b];
      if (u != v) bonds.emplace_back(std::min(u, v), std::max(u, v));
    }
  }
  std::sort(bonds.begin(), bonds.end());
  bonds.erase(std::unique(bonds.begin(), bonds.end()), bonds.end());
  // A box around the atoms, 5 % of the largest extent wider on every side (1 for a single point),
  // so that no atom lies on its faces.
  Vec3 lo(0, 0, 0), hi(0, 0, 0);
  if (!soup.points.empty()) {
    lo = hi = soup.points.front();
    for (const Vec3& p : soup.points) lo.minimize(p), hi.maximize(p);
  }
  const Vec3 extent = hi - lo;
  const double largest = std::max({extent[0], extent[1], extent[2]});
  const double pad = largest > 0 ? 0.05 * largest : 1.0;
  std::string out = "LAMMPS data file written by remeshd: one carbon atom per vertex, one bond per edge\n\n";
  out.reserve(soup.points.size() * 60 + bonds.size() * 24 + 256);
  append_uint(out, soup.points.size());
  out += " atoms\n";
  append_uint(out, bonds.size());
  out += " bonds\n1 atom types\n1 bond types\n\n";
  static const char* const axes[3] = {" xlo xhi\n", " ylo yhi\n", " zlo zhi\n"};
  for (int k = 0; k < 3; ++k) {
    append_number(out, lo[k] - pad);
    out += ' ';
    append_number(out, hi[k] + pad);
    out += axes[k];
  }
  out += "\nMasses\n\n1 12.011\n\nAtoms # bond\n\n";
  for (std::size_t i = 0; i < soup.points.size(); ++i) {
    append_uint(out, i + 1);
    out += " 1 1";  // molecule 1, atom type 1
    append_point(out, soup.points[i]);
  }
  // read_data refuses a Bonds section when the header counts none ("Invalid data file section").
  // The bond type stays declared: a script's bond_coeff 1 works for every file written here.
  if (!bonds.empty()) out += "\nBonds\n\n";
  for (std::size_t i = 0; i < bonds.size(); ++i) {
    append_uint(out, i + 1);
    out += " 1 ";  // bond type 1
    append_uint(out, std::uint64_t{bonds[i].first} + 1);
    out += ' ';
    append_uint(out, std::uint64_t{bonds[i].second} + 1);
    out += '\n';
  }
  return out;
}

}  // namespace remesh::io
