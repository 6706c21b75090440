/// \file triangulate.cpp
/// Ear clipping of one polygon, projected onto the plane of its Newell normal.

#include <cmath>

#include "io/repair.h"

namespace remesh::io {

namespace {

struct P2 {
  double x, y;
};

double cross(const P2& o, const P2& a, const P2& b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

bool inside(const P2& p, const P2& a, const P2& b, const P2& c) {
  return cross(a, b, p) >= 0 && cross(b, c, p) >= 0 && cross(c, a, p) >= 0;
}

void fan(const std::int64_t* idx, std::size_t n, std::vector<Tri>& out) {
  for (std::size_t i = 1; i + 1 < n; ++i)
    out.push_back({static_cast<std::uint32_t>(idx[0]), static_cast<std::uint32_t>(idx[i]),
                   static_cast<std::uint32_t>(idx[i + 1])});
}

}  // namespace

void triangulate_polygon(const std::vector<Vec3>& points, const std::int64_t* idx, std::size_t n,
                         std::vector<Tri>& out) {
  if (n == 3 || n > 256) return fan(idx, n, out);
  Vec3 normal(0, 0, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = points[static_cast<std::size_t>(idx[i])];
    const Vec3& b = points[static_cast<std::size_t>(idx[(i + 1) % n])];
    normal += Vec3((a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1]));
  }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(normal[k]) > std::abs(normal[axis])) axis = k;
  if (!(std::abs(normal[axis]) > 0)) return fan(idx, n, out);
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  const double sign = normal[axis] > 0 ? 1.0 : -1.0;  // makes the projected polygon counter-clockwise
  std::vector<P2> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& q = points[static_cast<std::size_t>(idx[i])];
    p[i] = {q[u], sign * q[v]};
  }
  std::vector<std::size_t> ring(n);
  for (std::size_t i = 0; i < n; ++i) ring[i] = i;
  std::size_t guard = 0, i = 0;
  while (ring.size() > 3 && guard < 2 * ring.size()) {
    const std::size_t m = ring.size();
    const std::size_t a = ring[(i + m - 1) % m], b = ring[i % m], c = ring[(i + 1) % m];
    bool ear = cross(p[a], p[b], p[c]) > 0;
    for (std::size_t k = 0; ear && k < m; ++k) {
      const std::size_t r = ring[k];
      if (r != a && r != b && r != c && inside(p[r], p[a], p[b], p[c])) ear = false;
    }
    if (ear) {
      out.push_back({static_cast<std::uint32_t>(idx[a]), static_cast<std::uint32_t>(idx[b]),
                     static_cast<std::uint32_t>(idx[c])});
      ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i % m));
      guard = 0;
      i = i % ring.size();
    } else {
      ++guard;
      i = (i + 1) % m;
    }
  }
  if (ring.size() > 3) {  // no ear found: self-intersecting; fan what is left
    std::vector<std::int64_t> rest;
    for (std::size_t r : ring) rest.push_back(idx[r]);
    return fan(rest.data(), rest.size(), out);
  }
  out.push_back({static_cast<std::uint32_t>(idx[ring[0]]), static_cast<std::uint32_t>(idx[ring[1]]),
                 static_cast<std::uint32_t>(idx[ring[2]])});
}

}  // namespace remesh::io
