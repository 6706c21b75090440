#include "remesh/crease_lines.h"

#include <algorithm>
#include <climits>
#include <cstdint>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "core/union_find.h"
#include "remesh/geometry.h"

namespace remesh {

namespace {

/// The edges sharper than kCreaseAngle, in connected groups of at least kMinCreaseEdges.
std::vector<OpenMesh::EdgeHandle> crease_edges(const TriMesh& mesh) {
  const double limit = std::cos(kCreaseAngle);
  const std::vector<Vec3> normals = geom::face_normals(mesh, 1);  // each face's once, not per edge
  std::vector<OpenMesh::EdgeHandle> sharp;
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted() || mesh.is_boundary(e)) continue;
    const Vec3& a = normals[mesh.face_handle(mesh.halfedge_handle(e, 0)).idx()];
    const Vec3& b = normals[mesh.face_handle(mesh.halfedge_handle(e, 1)).idx()];
    // A degenerate face has no direction to disagree with (as feature_snap.cpp's creases).
    if (a.sqrnorm() > 0 && b.sqrnorm() > 0 && !geom::normals_agree(a, b, limit)) sharp.push_back(e);
  }
  std::vector<std::uint32_t> parent(mesh.n_vertices());
  std::iota(parent.begin(), parent.end(), 0u);
  auto ends = [&](OpenMesh::EdgeHandle e) {
    const auto h = mesh.halfedge_handle(e, 0);
    return std::pair{static_cast<std::uint32_t>(mesh.from_vertex_handle(h).idx()),
                     static_cast<std::uint32_t>(mesh.to_vertex_handle(h).idx())};
  };
  for (auto e : sharp) {
    const auto [a, b] = ends(e);
    parent[find_root(parent, a)] = find_root(parent, b);
  }
  std::vector<std::uint32_t> count(mesh.n_vertices(), 0);
  for (auto e : sharp) ++count[find_root(parent, ends(e).first)];
  std::vector<OpenMesh::EdgeHandle> out;
  for (auto e : sharp)
    if (count[find_root(parent, ends(e).first)] >= kMinCreaseEdges) out.push_back(e);
  return out;
}

}  // namespace

CreaseLines::CreaseLines(const TriMesh& reference) : CreaseLines(reference, crease_edges(reference)) {}

CreaseLines::CreaseLines(const TriMesh& reference, const std::vector<OpenMesh::EdgeHandle>& edges)
    : samples_(std::vector<Vec3>{}) {
  points_.assign(reference.n_vertices(), Vec3(0, 0, 0));
  for (auto v : reference.vertices()) points_[v.idx()] = reference.point(v);
  std::vector<std::vector<std::uint32_t>> at(points_.size());  // the segments at each point
  for (auto e : edges) {
    const auto h = reference.halfedge_handle(e, 0);
    const auto a = static_cast<std::uint32_t>(reference.from_vertex_handle(h).idx());
    const auto b = static_cast<std::uint32_t>(reference.to_vertex_handle(h).idx());
    at[a].push_back(static_cast<std::uint32_t>(segments_.size()));
    at[b].push_back(static_cast<std::uint32_t>(segments_.size()));
    segments_.push_back({a, b});
  }
  // Points along each segment at most `step` apart: a point within tol of a segment is within
  // step / 2 + tol of one of its samples. The step is the median segment's length, so a query
  // looks at a few samples even where some creases are hundreds of times longer than the rest
  // (cheese), but at least 1/16 of the mean, so that a few long creases beside many short ones
  // cannot make the samples many (a 48-face prism 1e7 long, its caps' edges cut in 4: 4.5 GB).
  std::vector<double> lengths;
  for (const Segment& g : segments_) lengths.push_back((points_[g.a] - points_[g.b]).norm());
  double step = 0;
  if (!lengths.empty()) {
    const double total = std::accumulate(lengths.begin(), lengths.end(), 0.0);
    const auto middle = lengths.begin() + static_cast<long>(lengths.size() / 2);
    std::nth_element(lengths.begin(), middle, lengths.end());
    step = std::max(*middle, total / (16.0 * static_cast<double>(lengths.size())));
  }
  std::vector<Vec3> samples;
  for (std::uint32_t g = 0; g < segments_.size(); ++g) {
    const Vec3 &pa = points_[segments_[g].a], &pb = points_[segments_[g].b];
    // At most 17 samples a segment on average; a segment of length 0 (of no valid mesh) has its ends.
    const double pieces = step > 0 ? std::max(1.0, std::ceil((pb - pa).norm() / step)) : 1.0;
    for (double k = 0; k <= pieces; ++k) {
      samples.push_back(pa + (pb - pa) * (k / pieces));
      sample_segment_.push_back(g);
    }
  }
  reach_ = 0.5 * step;
  for (const Vec3& s : samples) box_.add(s);
  samples_ = PointIndex(std::move(samples));
  corner_.assign(points_.size(), 0);
  along_.assign(points_.size(), {0, 0});
  for (std::uint32_t q = 0; q < points_.size(); ++q) {
    if (at[q].empty()) continue;
    auto other = [&](std::uint32_t g) { return segments_[g].a == q ? segments_[g].b : segments_[g].a; };
    if (at[q].size() != 2) {
      corner_[q] = 1;
      continue;
    }
    const Vec3 in = points_[q] - points_[other(at[q][0])], out = points_[other(at[q][1])] - points_[q];
    const double lengths = in.norm() * out.norm();
    if (!(lengths > 0) || (in | out) < std::cos(kCreaseBend) * lengths) corner_[q] = 1;
    else along_[q] = {other(at[q][0]), other(at[q][1])};
  }
}

const std::vector<std::uint32_t>& CreaseLines::segments_near(const Vec3& p, double tol) const {
  thread_local std::vector<std::uint32_t> near, segments;
  segments.clear();
  const double radius = reach_ + tol * 2;
  if (box_.squared_distance(p) >= radius * radius) return segments;
  samples_.within(p, radius, near);
  for (std::uint32_t sample : near) {
    const std::uint32_t g = sample_segment_[sample];
    if (!segments.empty() && segments.back() == g) continue;  // a segment's samples are consecutive
    const Vec3 &a = points_[segments_[g].a], &b = points_[segments_[g].b];
    if ((geom::closest_point_on_segment(p, a, b) - p).sqrnorm() <= tol * tol) segments.push_back(g);
  }
  return segments;
}

CreaseLines::Where CreaseLines::locate(const Vec3& p, double tol) const {
  Where where;
  if (segments_.empty()) return where;
  std::uint32_t found = UINT32_MAX;
  for (std::uint32_t g : segments_near(p, tol)) {
    const Vec3 &a = points_[segments_[g].a], &b = points_[segments_[g].b];
    // At an end: that point's kind decides.
    for (std::uint32_t end : {segments_[g].a, segments_[g].b})
      if ((points_[end] - p).sqrnorm() <= tol * tol) {
        if (corner_[end]) return {Kind::Corner, {}, {}};
        return {Kind::Line, points_[along_[end][0]], points_[along_[end][1]]};
      }
    if (found != UINT32_MAX) return {Kind::Corner, {}, {}};  // two creases pass here
    found = g;
    where = {Kind::Line, a, b};
  }
  return where;
}

Vec3 CreaseLines::slide(const Vec3& p, const Where& where, const Vec3& t) {
  Vec3 best(0, 0, 0);
  double gain = 0;
  for (const Vec3& to : {where.ahead, where.back}) {
    const Vec3 d = to - p;
    const double length = d.norm();
    if (!(length > 0)) continue;
    const double s = (t | d) / length;
    if (s > gain) gain = s, best = d * (std::min(s, length) / length);
  }
  return best;
}

bool CreaseLines::joined(const Vec3& a, const Vec3& b, double tol, double max_arc,
                         std::vector<std::array<Vec3, 2>>* path) const {
  if (segments_.empty()) return false;
  auto near_segment = [&](const Vec3& p, const Vec3& s, const Vec3& t) {
    return (geom::closest_point_on_segment(p, s, t) - p).sqrnorm() <= tol * tol;
  };
  for (std::uint32_t g : segments_near(a, tol)) {
    const Vec3 &s = points_[segments_[g].a], &t = points_[segments_[g].b];
    const std::size_t kept = path ? path->size() : 0;
    if (path) path->push_back({s, t});
    if (near_segment(b, s, t)) return (b - a).norm() <= max_arc;
    // Walk from each end of a's segment along the crease, to b or a corner or max_arc.
    for (const auto& [from, to] : {std::pair{segments_[g].b, segments_[g].a}, std::pair{segments_[g].a, segments_[g].b}}) {
      std::uint32_t prev = from, at = to;
      double arc = (points_[at] - a).norm();
      const std::size_t start = path ? path->size() : 0;
      while (arc <= max_arc) {
        if ((points_[at] - b).sqrnorm() <= tol * tol) return true;  // b at this point (a corner too)
        if (corner_[at]) break;
        const std::uint32_t next = along_[at][0] == prev ? along_[at][1] : along_[at][0];
        if (path) path->push_back({points_[at], points_[next]});
        if (near_segment(b, points_[at], points_[next])) return arc + (b - points_[at]).norm() <= max_arc;
        arc += (points_[next] - points_[at]).norm();
        prev = at, at = next;
      }
      if (path) path->resize(start);
    }
    if (path) path->resize(kept);
  }
  return false;
}

bool CreaseGuard::along(const Vec3& a, const Vec3& b) const {
  // joined() finds a's segments and b on the path itself: no locate() of the ends first (two
  // kd-tree searches more in every flip check).
  return !empty() && lines_->joined(a, b, tol_, kArcShare * (b - a).norm() + tol_);
}

bool CreaseGuard::along(const TriMesh& mesh, OpenMesh::EdgeHandle e) const {
  if (empty() || mesh.is_boundary(e)) return false;
  const auto h = mesh.halfedge_handle(e, 0);
  const Vec3 n0 = geom::face_normal(mesh, mesh.face_handle(h));
  const Vec3 n1 = geom::face_normal(mesh, mesh.opposite_face_handle(h));
  if (geom::normals_agree(n0, n1, kAlongCos)) return false;
  return along(mesh.point(mesh.from_vertex_handle(h)), mesh.point(mesh.to_vertex_handle(h)));
}

Vec3 CreaseGuard::onto(const Vec3& p, const Vec3& a, const Vec3& b) const {
  thread_local std::vector<std::array<Vec3, 2>> path;
  path.clear();
  if (!lines_->joined(a, b, tol_, kArcShare * (b - a).norm() + tol_, &path)) return p;
  Vec3 best = p;
  double nearest = std::numeric_limits<double>::infinity();
  for (const auto& [s, t] : path) {
    const Vec3 q = geom::closest_point_on_segment(p, s, t);
    const double d = (q - p).sqrnorm();
    if (d < nearest) nearest = d, best = q;
  }
  return best;
}

Vec3 CreaseGuard::constrain(const Vec3& p, const CreaseLines::Where& where, const Vec3& x) {
  switch (where.kind) {
    case CreaseLines::Kind::None: return x;
    case CreaseLines::Kind::Corner: return p;
    case CreaseLines::Kind::Line: break;
  }
  return p + CreaseLines::slide(p, where, x - p);
}

}  // namespace remesh
