/// \file build_mesh.cpp
/// Validation and repair of a reader's polygon soup into a TriMesh. Order: refuse non-finite
/// points, short faces and bad indices; triangulate polygons; weld (if asked); drop faces with a
/// repeated vertex and duplicate faces (zero-area ones are kept, but those on an edge with more
/// than two faces); refuse non-manifold edges; orient; split pinched vertices; drop unreferenced
/// vertices; build the half-edge mesh; repair the zero-area faces on it (degenerate_faces.h),
/// dropping those it cannot.

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include "io/degenerate_faces.h"
#include "io/parse_util.h"
#include "io/point_hash.h"
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
        fail("face " + std::to_string(f) + raw.face_where(f) + " refers to vertex " +
             std::to_string(raw.indices[k] + raw.index_base) + ", but there " +
             (nv == 1 ? "is 1 vertex" : "are " + std::to_string(nv) + " vertices") +
             (raw.index_base == 1 ? " (OBJ counts from 1)" : " (0-based indices)"));
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
      std::uint64_t bits[3];
      for (int i = 0; i < 3; ++i) {
        const double v = p[i] + 0.0;  // -0.0 == 0.0
        std::memcpy(&bits[i], &v, 8);
      }
      return static_cast<std::size_t>(point_hash(bits));
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

bool repeats_a_vertex(const Tri& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

/// Drops faces with a repeated vertex and duplicates; flags the zero-area ones, kept for repair.
void drop_bad_faces(TriSoup& soup, DroppedFaces& dropped, const RawSoup& raw, std::vector<Repair>& repairs) {
  std::size_t duplicate_count = 0;
  std::string first_duplicate;
  std::vector<bool> keep(soup.tris.size(), true);
  soup.zero_area.assign(soup.tris.size(), false);
  for (std::size_t t = 0; t < soup.tris.size(); ++t) {
    const Tri& tri = soup.tris[t];
    if (repeats_a_vertex(tri)) {
      keep[t] = false;
      if (dropped.repeated++ == 0) dropped.first_repeated = soup.source[t];
    } else if (zero_area(soup.points[tri[0]], soup.points[tri[1]], soup.points[tri[2]])) {
      soup.zero_area[t] = true;
    }
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
  if (dropped.repeated + duplicate_count > 0) soup.retain(keep);
  if (duplicate_count > 0)
    repairs.push_back({"duplicate_faces_removed", duplicate_count,
                       std::to_string(duplicate_count) + " duplicate faces dropped (first: " + first_duplicate + ")"});
}

bool has_zero_area(const TriSoup& soup) {
  return std::find(soup.zero_area.begin(), soup.zero_area.end(), true) != soup.zero_area.end();
}

/// check_edges_and_orient() with the zero-area faces kept; if it fails with them (one can close a
/// cycle that cannot be oriented), again without any of them, as the input read before they were
/// kept: nothing read then is refused now.
std::vector<EdgeUse> orient(TriSoup& soup, DroppedFaces& dropped, const RawSoup& raw, std::vector<Repair>& repairs) {
  if (!has_zero_area(soup)) return check_edges_and_orient(soup, raw, repairs);
  const std::vector<Tri> before = soup.tris;
  try {
    return check_edges_and_orient(soup, raw, repairs);
  } catch (const MeshError&) {
    soup.tris = before;
    std::vector<bool> keep(soup.tris.size(), true);
    for (std::size_t t = 0; t < soup.tris.size(); ++t)
      if (soup.zero_area[t]) keep[t] = false, dropped.add_zero_area(soup.source[t]);
    soup.retain(keep);
    return check_edges_and_orient(soup, raw, repairs);
  }
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

std::string face_name(const RawSoup& raw, std::uint32_t f) {
  return "face " + std::to_string(f) + raw.face_where(f);
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// Repairs the zero-area triangles on the half-edge mesh (degenerate_faces.h). Those it leaves are
/// dropped through the soup again, which splits any vertex their going pinches. Appends the
/// "degenerate_faces_repaired" report to `report`.
TriMesh repair_zero_area(TriMesh mesh, const TriSoup& soup, DroppedFaces& dropped, const RawSoup& raw,
                         std::vector<Repair>& report) {
  std::vector<OpenMesh::FaceHandle> faces;
  for (std::size_t t = 0; t < soup.tris.size(); ++t)
    if (soup.zero_area[t]) faces.push_back(OpenMesh::FaceHandle(static_cast<int>(t)));
  const ZeroAreaRepair r = repair_zero_area_faces(mesh, faces);
  std::vector<bool> left(mesh.n_faces(), false);
  for (const auto f : r.left) {
    left[f.idx()] = true;
    dropped.add_zero_area(soup.source[f.idx()]);
  }
  const std::size_t repaired = faces.size() > r.left.size() ? faces.size() - r.left.size() : 0;
  if (repaired > 0) {
    const auto first = std::find_if(faces.begin(), faces.end(), [&](auto f) { return !left[f.idx()]; });
    report.push_back(
        {"degenerate_faces_repaired", repaired,
         plural(repaired, "zero-area face", "zero-area faces") + " repaired by collapsing their near-zero edge or "
             "flipping the edge they lie on (or removing them where that edge is on the boundary), the surface kept "
             "whole (first: " + face_name(raw, soup.source[first->idx()]) + "; " +
             plural(r.collapses, "collapse", "collapses") + ", " + plural(r.flips, "flip", "flips") + ", " +
             plural(r.boundary_deletions, "removal", "removals") + ")"});
  }
  if (r.left.empty()) {
    collect_garbage(mesh);
    mesh.update_normals();
    return mesh;
  }
  TriSoup rest;
  std::vector<std::uint32_t> index(mesh.n_vertices(), UINT32_MAX);
  for (const auto v : mesh.vertices()) {
    index[v.idx()] = static_cast<std::uint32_t>(rest.points.size());
    rest.points.push_back(mesh.point(v));
  }
  for (const auto f : mesh.faces()) {
    if (left[f.idx()]) continue;
    Tri& tri = rest.tris.emplace_back();
    int c = 0;
    for (const auto v : mesh.fv_range(f)) tri[c++] = index[v.idx()];
    rest.source.push_back(soup.source[f.idx()]);
  }
  free_mesh(mesh);
  // Oriented and manifold already: nothing is refused or flipped. What remains to report (vertices
  // split or left unused) goes into the report of the dropped faces.
  std::vector<Repair> side;
  const std::vector<EdgeUse> uses = check_edges_and_orient(rest, raw, side);
  split_pinched_vertices(rest, uses, side);
  compact(rest, side);
  for (const Repair& s : side) {
    if (s.kind == "nonmanifold_vertices_split") dropped.pinched += s.count;
    if (s.kind == "unreferenced_vertices_removed") dropped.unused += s.count;
  }
  return assemble(rest);
}

/// The "degenerate_faces_removed" report.
Repair dropped_report(const DroppedFaces& d, const RawSoup& raw) {
  std::string detail = plural(d.repeated + d.zero_area, "degenerate face", "degenerate faces") + " dropped: ";
  if (d.repeated > 0)
    detail +=
        std::to_string(d.repeated) + " with a repeated vertex (first: " + face_name(raw, d.first_repeated) + ")";
  if (d.repeated > 0 && d.zero_area > 0) detail += ", ";
  if (d.zero_area > 0) {
    detail += std::to_string(d.zero_area) + " of zero area that could not be kept (an edge with more than 2 faces) "
              "or repaired (first: " + face_name(raw, d.first_zero_area) + ")";
    if (d.pinched > 0) detail += ", which left " + plural(d.pinched, "vertex", "vertices") + " pinched (split)";
    if (d.unused > 0)
      detail += (d.pinched > 0 ? " and " : ", which left ") + plural(d.unused, "vertex", "vertices") +
                " unused (dropped)";
    detail += "; where one closed the surface a hole may be left there, and the remeshed surface keeps it "
              "(--weld / weld=true merges coincident vertices first)";
  }
  return {"degenerate_faces_removed", d.repeated + d.zero_area, detail};
}

[[noreturn]] void fail_no_surface(const RawSoup& raw) {
  fail("all " + std::to_string(raw.face_count()) + " faces are degenerate or duplicates; no surface is left");
}

}  // namespace

void TriSoup::retain(const std::vector<bool>& keep) {
  std::size_t out = 0;
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (keep[t]) {
      tris[out] = tris[t];
      source[out] = source[t];
      if (!zero_area.empty()) zero_area[out] = zero_area[t];
      ++out;
    }
  tris.resize(out);
  source.resize(out);
  if (!zero_area.empty()) zero_area.resize(out);
}

TriMesh build_mesh(RawSoup raw, const ReadOptions& options, std::vector<Repair>& repairs) {
  if (raw.face_count() == 0)
    fail(raw.points.empty() ? "the input holds no vertices and no faces" : "the input has " +
         std::to_string(raw.points.size()) + " vertices but no faces (a point cloud has no surface)");
  validate(raw);
  TriSoup soup = triangulate(raw, options, repairs);
  check_face_limit(soup.tris.size(), options, "the triangulated mesh");
  if (options.weld) weld(soup, repairs);
  const std::size_t degenerate_at = repairs.size();  // their reports go here, once all are known
  DroppedFaces dropped;
  drop_bad_faces(soup, dropped, raw, repairs);
  if (soup.tris.empty()) fail_no_surface(raw);
  if (has_zero_area(soup)) drop_crowding_zero_area(soup, dropped);
  const std::vector<EdgeUse> uses = orient(soup, dropped, raw, repairs);
  split_pinched_vertices(soup, uses, repairs);
  compact(soup, repairs);
  TriMesh mesh = assemble(soup);
  std::vector<Repair> degenerate;
  if (has_zero_area(soup)) mesh = repair_zero_area(std::move(mesh), soup, dropped, raw, degenerate);
  if (dropped.repeated + dropped.zero_area > 0) degenerate.push_back(dropped_report(dropped, raw));
  repairs.insert(repairs.begin() + static_cast<std::ptrdiff_t>(degenerate_at), degenerate.begin(), degenerate.end());
  if (mesh.n_faces() == 0) fail_no_surface(raw);
  return mesh;
}

}  // namespace remesh::io
