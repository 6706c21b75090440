/// \file build_mesh.cpp
/// Validation and repair of a reader's polygon soup into a TriMesh. Order: refuse non-finite
/// points, short faces and bad indices; triangulate polygons; weld (if asked); drop degenerate
/// and duplicate faces; refuse non-manifold edges; orient; split pinched vertices; drop
/// unreferenced vertices; build the half-edge mesh.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include "io/parse_util.h"
#include "io/repair.h"

namespace remesh::io {

namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

void validate(const RawSoup& raw) {
  for (std::size_t i = 0; i < raw.points.size(); ++i) {
    const Vec3& p = raw.points[i];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      fail("vertex " + std::to_string(i) + raw.point_where(i) + " has a non-finite coordinate (" + num(p[0]) + ", " +
           num(p[1]) + ", " + num(p[2]) + ")");
  }
  const auto nv = static_cast<std::int64_t>(raw.points.size());
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    const std::uint32_t b = raw.offsets[f], e = raw.offsets[f + 1];
    if (e - b < 3)
      fail("face " + std::to_string(f) + raw.face_where(f) + " has " + std::to_string(e - b) +
           " vertices; a face needs at least 3");
    for (std::uint32_t k = b; k < e; ++k)
      if (raw.indices[k] < 0 || raw.indices[k] >= nv)
        fail("face " + std::to_string(f) + raw.face_where(f) + " refers to vertex " + std::to_string(raw.indices[k]) +
             ", but there " + (nv == 1 ? "is 1 vertex" : "are " + std::to_string(nv) + " vertices") +
             " (0-based indices)");
  }
}

TriSoup triangulate(RawSoup& raw, const ReadOptions& options, std::vector<Repair>& repairs) {
  TriSoup soup;
  soup.tris.reserve(raw.face_count());
  soup.source.reserve(raw.face_count());
  std::size_t polygons = 0, before = 0;
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    const std::uint32_t b = raw.offsets[f], n = raw.offsets[f + 1] - b;
    if (n > 3) ++polygons;
    if (n > 3 && options.max_faces > 0) check_face_limit(soup.tris.size() + n - 2, options, "the triangulated mesh");
    before = soup.tris.size();
    triangulate_polygon(raw.points, raw.indices.data() + b, n, soup.tris);
    soup.source.resize(soup.tris.size(), static_cast<std::uint32_t>(f));
  }
  (void)before;
  if (polygons > 0)
    repairs.push_back({"polygons_triangulated", polygons,
                       std::to_string(polygons) + " polygons with more than 3 sides triangulated (" +
                           std::to_string(soup.tris.size()) + " triangles from " + std::to_string(raw.face_count()) +
                           " faces)"});
  soup.points = std::move(raw.points);
  return soup;
}

void weld(TriSoup& soup, std::vector<Repair>& repairs) {
  struct Hash {
    std::size_t operator()(const Vec3& p) const {
      std::uint64_t h = 1469598103934665603ull;
      for (int i = 0; i < 3; ++i) {
        double v = p[i] + 0.0;
        std::uint64_t b;
        std::memcpy(&b, &v, 8);
        h = (h ^ b) * 1099511628211ull ^ (h >> 31);
      }
      return static_cast<std::size_t>(h);
    }
  };
  std::unordered_map<Vec3, std::uint32_t, Hash> first;
  first.reserve(soup.points.size());
  std::vector<std::uint32_t> map(soup.points.size());
  for (std::uint32_t i = 0; i < soup.points.size(); ++i) map[i] = first.try_emplace(soup.points[i], i).first->second;
  const std::vector<Tri> original = soup.tris;
  auto apply = [&] {
    for (std::size_t t = 0; t < original.size(); ++t)
      for (int c = 0; c < 3; ++c) soup.tris[t][c] = map[original[t][c]];
  };
  // Weld only where the surface stays manifold: a welded vertex on an edge that would then have
  // more than two faces is unwelded again (with its whole group), a few rounds at most.
  for (int round = 0; round < 8; ++round) {
    apply();
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    edges.reserve(3 * soup.tris.size());
    for (const Tri& t : soup.tris) {
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
      for (int c = 0; c < 3; ++c) edges.push_back(std::minmax(t[c], t[(c + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    std::vector<bool> crowded(soup.points.size(), false);
    for (std::size_t i = 0; i + 2 < edges.size(); ++i)
      if (edges[i] == edges[i + 2]) crowded[edges[i].first] = crowded[edges[i].second] = true;
    bool changed = false;
    for (std::uint32_t i = 0; i < map.size(); ++i)
      if (map[i] != i && crowded[map[i]]) map[i] = i, changed = true;
    if (!changed) break;
  }
  apply();
  std::size_t welded = 0;
  soup.welded_away.assign(soup.points.size(), false);
  for (std::uint32_t i = 0; i < map.size(); ++i)
    if (map[i] != i) ++welded, soup.welded_away[i] = true;
  if (welded == 0) return;
  repairs.push_back({"vertices_welded", welded,
                     std::to_string(welded) + " duplicate vertices at identical positions welded"});
}

/// Twice the area is below 1e-12 of the longest edge squared: zero within double rounding.
/// Computed on points scaled by their largest coordinate so huge or tiny values cannot overflow.
bool degenerate(const TriSoup& soup, const Tri& t) {
  if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return true;
  const Vec3 &a = soup.points[t[0]], &b = soup.points[t[1]], &c = soup.points[t[2]];
  const double m = std::max({a.max_abs(), b.max_abs(), c.max_abs()});
  if (!(m > 0)) return true;
  const Vec3 sa = a / m, sb = b / m, sc = c / m;
  const double twice_area = OpenMesh::cross(sb - sa, sc - sa).norm();
  const double longest = std::max({(sb - sa).sqrnorm(), (sc - sb).sqrnorm(), (sa - sc).sqrnorm()});
  return !(twice_area > 1e-12 * longest);
}

void drop_bad_faces(TriSoup& soup, const RawSoup& raw, std::vector<Repair>& repairs) {
  std::size_t degenerate_count = 0, duplicate_count = 0;
  std::string first_degenerate, first_duplicate;
  std::vector<bool> keep(soup.tris.size(), true);
  for (std::size_t t = 0; t < soup.tris.size(); ++t)
    if (degenerate(soup, soup.tris[t])) {
      keep[t] = false;
      if (degenerate_count++ == 0)
        first_degenerate = "face " + std::to_string(soup.source[t]) + raw.face_where(soup.source[t]);
    }
  // Duplicates: the same three vertices in any order; the first one is kept.
  std::vector<std::pair<Tri, std::uint32_t>> keys;
  keys.reserve(soup.tris.size());
  for (std::uint32_t t = 0; t < soup.tris.size(); ++t) {
    if (!keep[t]) continue;
    Tri k = soup.tris[t];
    std::sort(k.begin(), k.end());
    keys.push_back({k, t});
  }
  std::sort(keys.begin(), keys.end());
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i].first == keys[i - 1].first) {
      keep[keys[i].second] = false;
      if (duplicate_count++ == 0)
        first_duplicate = "face " + std::to_string(soup.source[keys[i].second]) + raw.face_where(soup.source[keys[i].second]);
    }
  if (degenerate_count + duplicate_count == 0) return;
  std::size_t out = 0;
  for (std::size_t t = 0; t < soup.tris.size(); ++t)
    if (keep[t]) {
      soup.tris[out] = soup.tris[t];
      soup.source[out++] = soup.source[t];
    }
  soup.tris.resize(out);
  soup.source.resize(out);
  if (degenerate_count > 0)
    repairs.push_back({"degenerate_faces_removed", degenerate_count,
                       std::to_string(degenerate_count) + " zero-area faces dropped (first: " + first_degenerate +
                           "); where such a face closed the surface a hole is left, and the remeshed surface "
                           "keeps it (--weld / weld=true merges coincident vertices first)"});
  if (duplicate_count > 0)
    repairs.push_back({"duplicate_faces_removed", duplicate_count,
                       std::to_string(duplicate_count) + " duplicate faces dropped (first: " + first_duplicate + ")"});
}

/// Drops unreferenced points, renumbering the rest in order.
void compact(TriSoup& soup, std::vector<Repair>& repairs) {
  std::vector<std::uint32_t> map(soup.points.size(), UINT32_MAX);
  for (const Tri& t : soup.tris)
    for (auto v : t) map[v] = 0;
  std::uint32_t next = 0;
  std::size_t unused = 0;
  std::string first;
  for (std::size_t i = 0; i < map.size(); ++i) {
    if (map[i] == UINT32_MAX) {
      if (i < soup.welded_away.size() && soup.welded_away[i]) continue;  // reported as welded
      if (unused++ == 0) first = std::to_string(i);
      continue;
    }
    map[i] = next;
    soup.points[next++] = soup.points[i];
  }
  soup.points.resize(next);
  if (next == map.size()) return;
  for (Tri& t : soup.tris)
    for (auto& v : t) v = map[v];
  if (unused > 0)
    repairs.push_back({"unreferenced_vertices_removed", unused,
                     std::to_string(unused) + " vertices used by no face dropped (first: vertex " + first + ")"});
}

TriMesh assemble(const TriSoup& soup) {
  TriMesh mesh;
  mesh.reserve(soup.points.size(), soup.points.size() + soup.tris.size() * 3 / 2 + 3, soup.tris.size());
  std::vector<TriMesh::VertexHandle> vh;
  vh.reserve(soup.points.size());
  for (const Vec3& p : soup.points) vh.push_back(mesh.add_vertex(p));
  for (std::size_t t = 0; t < soup.tris.size(); ++t) {
    const Tri& tri = soup.tris[t];
    if (!mesh.add_face(vh[tri[0]], vh[tri[1]], vh[tri[2]]).is_valid())
      throw std::logic_error("internal error: the half-edge mesh refused repaired triangle " + std::to_string(t) +
                             " (input face " + std::to_string(soup.source[t]) + ")");
  }
  mesh.update_normals();
  return mesh;
}

}  // namespace

TriMesh build_mesh(RawSoup raw, const ReadOptions& options, std::vector<Repair>& repairs) {
  if (raw.face_count() == 0)
    fail(raw.points.empty() ? "the input holds no vertices and no faces" : "the input has " +
         std::to_string(raw.points.size()) + " vertices but no faces (a point cloud has no surface)");
  validate(raw);
  TriSoup soup = triangulate(raw, options, repairs);
  check_face_limit(soup.tris.size(), options, "the triangulated mesh");
  if (options.weld) weld(soup, repairs);
  drop_bad_faces(soup, raw, repairs);
  if (soup.tris.empty())
    fail("all " + std::to_string(raw.face_count()) + " faces are degenerate or duplicates; no surface is left");
  const std::vector<EdgeUse> uses = check_edges_and_orient(soup, raw, repairs);
  split_pinched_vertices(soup, uses, repairs);
  compact(soup, repairs);
  return assemble(soup);
}

}  // namespace remesh::io
