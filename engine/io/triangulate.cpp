/// \file triangulate.cpp
/// Ear clipping of one polygon, projected onto the plane of its Newell normal.

#include <algorithm>
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

/// Corners up to which triangulate_polygon() clips ears by scanning the whole ring for each; larger
/// polygons go to ear_clip_large().
constexpr std::size_t kSmallPolygon = 256;

/// Corners looked at and point-in-ear tests ear_clip_large() makes at most, a polygon, before it
/// fans what is left (about 0.2 s): a polygon of 100 000 corners, half of them reflex, would take
/// ~10^9 tests.
constexpr std::size_t kLargeWork = 50'000'000;

/// Ear clipping of a polygon of more than kSmallPolygon corners, projected to `p` (counter-
/// clockwise). The ring is a linked list, and an ear is tested against the reflex corners only
/// (a corner inside an ear implies a reflex one inside it), those in the grid cells its box
/// covers; a convex polygon takes linear time.
/// Ears are taken in the order the scan for 256 corners or fewer takes them; after kLargeWork
/// steps and tests, or when no ear is left (a self-intersecting polygon), the rest is fanned from
/// its first corner.
/// Measured: a star-shaped 2 400-gon (radii alternating 1 and 0.8) 0.03 s.
void ear_clip_large(const std::vector<P2>& p, const std::int64_t* idx, std::size_t n, std::vector<Tri>& out) {
  std::vector<std::size_t> prev(n), next(n);
  for (std::size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
  auto convex = [&](std::size_t b) { return cross(p[prev[b]], p[b], p[next[b]]) > 0; };
  std::vector<char> reflex(n, 0);
  std::vector<std::size_t> reflex_corners;
  for (std::size_t i = 0; i < n; ++i)
    if (!convex(i)) reflex[i] = 1, reflex_corners.push_back(i);
  // The reflex corners in a uniform grid over the polygon's box, about two a cell, so that an ear
  // is tested against those in the cells its box covers (a corner that turns convex stays listed,
  // passed over). floor() is monotonic: a corner within the ear's box lies in one of those cells.
  double lo_x = p[0].x, hi_x = lo_x, lo_y = p[0].y, hi_y = lo_y;
  for (const P2& q : p) {
    lo_x = std::min(lo_x, q.x), hi_x = std::max(hi_x, q.x);
    lo_y = std::min(lo_y, q.y), hi_y = std::max(hi_y, q.y);
  }
  const std::size_t side = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::sqrt(static_cast<double>(reflex_corners.size()) / 2)), 1, 1024);
  const double cell_x = (hi_x - lo_x) / static_cast<double>(side), cell_y = (hi_y - lo_y) / static_cast<double>(side);
  auto cell_of = [&](double v, double lo, double size) {
    const double k = size > 0 ? std::floor((v - lo) / size) : 0.0;
    // Not a number (a box so wide its size overflowed: inf / inf) counts as the first cell.
    return k > 0 ? static_cast<std::size_t>(std::min(k, static_cast<double>(side - 1))) : std::size_t{0};
  };
  std::vector<std::size_t> start(side * side + 1, 0), in_cell(reflex_corners.size());
  for (std::size_t r : reflex_corners) ++start[cell_of(p[r].y, lo_y, cell_y) * side + cell_of(p[r].x, lo_x, cell_x) + 1];
  for (std::size_t c = 0; c < side * side; ++c) start[c + 1] += start[c];
  {
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t r : reflex_corners)
      in_cell[fill[cell_of(p[r].y, lo_y, cell_y) * side + cell_of(p[r].x, lo_x, cell_x)]++] = r;
  }
  auto emit = [&](std::size_t a, std::size_t b, std::size_t c) {
    out.push_back({static_cast<std::uint32_t>(idx[a]), static_cast<std::uint32_t>(idx[b]),
                   static_cast<std::uint32_t>(idx[c])});
  };
  std::size_t m = n, cur = 0, guard = 0, work = 0;
  while (m > 3 && guard < 2 * m && work < kLargeWork) {
    ++work;
    const std::size_t a = prev[cur], b = cur, c = next[cur];
    bool ear = cross(p[a], p[b], p[c]) > 0;
    if (ear) {
      const std::size_t x0 = cell_of(std::min({p[a].x, p[b].x, p[c].x}), lo_x, cell_x),
                        x1 = cell_of(std::max({p[a].x, p[b].x, p[c].x}), lo_x, cell_x),
                        y0 = cell_of(std::min({p[a].y, p[b].y, p[c].y}), lo_y, cell_y),
                        y1 = cell_of(std::max({p[a].y, p[b].y, p[c].y}), lo_y, cell_y);
      for (std::size_t y = y0; ear && y <= y1; ++y)
        for (std::size_t k = start[y * side + x0]; ear && k < start[y * side + x1 + 1]; ++k) {
          const std::size_t r = in_cell[k];
          if (!reflex[r] || r == a || r == c) continue;
          ++work;
          if (inside(p[r], p[a], p[b], p[c])) ear = false;
        }
    }
    if (!ear) {
      ++guard;
      cur = c;
      continue;
    }
    emit(a, b, c);  // b, an ear's tip, is convex: not reflex
    next[a] = c, prev[c] = a;
    --m;
    // Clipping an ear takes its angle off the angles at its ends: a reflex end may turn convex,
    // never the other way.
    for (std::size_t end : {a, c})
      if (reflex[end] && convex(end)) reflex[end] = 0;
    guard = 0;
    cur = c;
  }
  // What is left, from its first corner (in the polygon's order), as a triangle or a fan.
  std::size_t first = cur;
  for (std::size_t k = 0, v = cur; k < m; ++k, v = next[v]) first = std::min(first, v);
  std::vector<std::int64_t> rest;
  rest.reserve(m);
  for (std::size_t k = 0, v = first; k < m; ++k, v = next[v]) rest.push_back(idx[v]);
  fan(rest.data(), rest.size(), out);
}

}  // namespace

void triangulate_polygon(const std::vector<Vec3>& points, const std::int64_t* idx, std::size_t n,
                         std::vector<Tri>& out) {
  if (n == 3) return fan(idx, n, out);
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
  if (n > kSmallPolygon) return ear_clip_large(p, idx, n, out);
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
