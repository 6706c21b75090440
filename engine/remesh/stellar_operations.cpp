#include "remesh/stellar_operations.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "remesh/geometry.h"
#include "remesh/reposition.h"

namespace remesh {

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;

bool component_larger_than(const TriMesh& mesh, VertexHandle v, std::size_t n) {
  std::vector<VertexHandle> seen{v};  // at most n + 1: a linear search is fine
  if (seen.size() > n) return true;
  for (std::size_t i = 0; i < seen.size(); ++i)
    for (auto w : mesh.vv_range(seen[i])) {
      if (std::find(seen.begin(), seen.end(), w) != seen.end()) continue;
      seen.push_back(w);
      if (seen.size() > n) return true;
    }
  return false;
}

namespace {

/// Not in the thesis: how much smaller than the sliver it replaces (relatively) a triangle a split
/// may make, below kMinAngle. Splitting the long side of a triangle with a tiny angle theta at its
/// midpoint keeps theta at that corner but leaves one of theta * (1 - ~theta^2) at another; with no
/// slack such a split is refused wherever it is placed (the two triangles of the edge want the
/// point on opposite sides of the midpoint). A mesh of slivers then stalls unchanged: a disk cut
/// into 600 sectors around its centre (0.6 degrees each), a cylinder of 500 segments with such
/// caps (0 % and 61 % inside; 100 % with the slack, the cylinder in 0.5 s instead of 14). 1e-3
/// covers theta up to kMinAngle. Of the Table 4.2 runs only those with slivers in their input
/// change (cheese, camelhead, nefertiti, bunny_zipper refined; cheese, nefertiti simplified): the
/// means over the five intervals of bench --spread, inside % / Hausdorff % of the diagonal, before
/// -> after: cheese refined 99.618 / 3.08 -> 99.647 / 2.98, simplified 64.75 / 6.06 -> 66.39 / 6.00
/// (regular 18.5 -> 16.9 %), nefertiti refined 99.995 / 0.188 -> 99.996 / 0.178, camelhead refined
/// 99.980 / 0.81 -> 99.980 / 0.84.
constexpr double kSplitAngleSlack = 1e-3;

/// Would the triangles made by splitting e at p be non-degenerate (no worse than kMinAngle, or than
/// the triangle they replace, up to kSplitAngleSlack) and unfolded? (A point on the edge leaves them
/// in the old triangle's plane; one off it, on a crease (CreaseGuard::onto), tilts them.)
bool split_point_ok(const TriMesh& mesh, EdgeHandle e, const Vec3& p) {
  for (int s = 0; s < 2; ++s) {
    const HalfedgeHandle h = mesh.halfedge_handle(e, s);
    if (mesh.is_boundary(h)) continue;
    const Vec3& a = mesh.point(mesh.from_vertex_handle(h));
    const Vec3& b = mesh.point(mesh.to_vertex_handle(h));
    const Vec3& c = mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h)));
    geom::AngleFloor floor([&] { return geom::min_angle(a, b, c); }, kSplitAngleSlack);
    if (floor.breaks(a, p, c) || floor.breaks(p, b, c)) return false;
    const Vec3 before = geom::cross_normal(a, b, c);
    if (!geom::normals_agree(before, geom::cross_normal(a, p, c)) || !geom::normals_agree(before, geom::cross_normal(p, b, c)))
      return false;
  }
  return true;
}

}  // namespace

VertexHandle split_edge(TriMesh& mesh, EdgeHandle e, double target, const CreaseGuard* creases) {
  const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
  const VertexHandle v0 = mesh.from_vertex_handle(h);
  const Vec3 a = mesh.point(v0), b = mesh.point(mesh.to_vertex_handle(h));
  const double t = equalizing_parameter(a, b, split_neighbours(mesh, e), target);
  // An edge along a crease: its points go onto the crease (the chord of a bent one sags below it).
  const bool crease = creases && creases->along(mesh, e);
  auto placed = [&](const Vec3& q) { return crease ? creases->onto(q, a, b) : q; };
  Vec3 p = placed(a + (b - a) * t);
  if (!split_point_ok(mesh, e, p)) {
    p = placed((a + b) * 0.5);
    if (!split_point_ok(mesh, e, p)) return VertexHandle();
  }
  return mesh.split(e, p);
}

bool collapse_geometry_ok(const TriMesh& mesh, HalfedgeHandle h, const Vec3& p, double max_length, bool turned_ok) {
  const VertexHandle v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
  const FaceHandle gone0 = mesh.face_handle(h), gone1 = mesh.face_handle(mesh.opposite_halfedge_handle(h));
  geom::AngleFloor floor([&] { return std::min(geom::star_min_angle(mesh, v0), geom::star_min_angle(mesh, v1)); });
  for (VertexHandle end : {v0, v1}) {
    for (auto f : mesh.vf_range(end)) {
      if (f == gone0 || f == gone1) continue;
      VertexHandle c[3];
      geom::face_vertices(mesh, f, c);
      Vec3 q[3];
      for (int k = 0; k < 3; ++k) q[k] = (c[k] == v0 || c[k] == v1) ? p : mesh.point(c[k]);
      const Vec3 n_after = geom::cross_normal(q[0], q[1], q[2]);
      if (!turned_ok && !geom::normals_agree(geom::face_normal(mesh, f), n_after)) return false;
      if (floor.breaks(q[0], q[1], q[2])) return false;
      // No fold against a neighbour (those across the removed faces are not checked).
      for (auto g : mesh.ff_range(f)) {
        if (g == gone0 || g == gone1) continue;
        VertexHandle d[3];
        geom::face_vertices(mesh, g, d);
        Vec3 r[3];
        for (int k = 0; k < 3; ++k) r[k] = (d[k] == v0 || d[k] == v1) ? p : mesh.point(d[k]);
        if (!geom::adjacent_ok(geom::face_normal(mesh, f), geom::face_normal(mesh, g), n_after,
                               geom::cross_normal(r[0], r[1], r[2])))
          return false;
      }
    }
    for (auto w : mesh.vv_range(end)) {
      if (w == v0 || w == v1) continue;
      if ((mesh.point(w) - p).norm() > max_length) return false;
    }
  }
  // Each removed face (v0, v1, c) takes its edges v0-c and v1-c with it: the faces across them
  // become neighbours across the merged edge, and may not fold against each other either (the
  // pair was bent over the removed face before; it may stay as sharp, not become sharper). Without
  // this check, collapses on tori whose tube is too thin for the interval left faces folded back
  // onto each other in 11 of 20 runs (tube radius 0.45-0.6, [1.2, 1.8], 100 iterations), with it in 4.
  for (const HalfedgeHandle g : {h, mesh.opposite_halfedge_handle(h)}) {
    if (mesh.is_boundary(g)) continue;
    const HalfedgeHandle next = mesh.next_halfedge_handle(g), prev = mesh.prev_halfedge_handle(g);
    const FaceHandle a = mesh.opposite_face_handle(next), b = mesh.opposite_face_handle(prev);
    if (!a.is_valid() || !b.is_valid()) continue;
    auto moved = [&](FaceHandle f) {
      VertexHandle c[3];
      geom::face_vertices(mesh, f, c);
      Vec3 q[3];
      for (int k = 0; k < 3; ++k) q[k] = (c[k] == v0 || c[k] == v1) ? p : mesh.point(c[k]);
      return geom::cross_normal(q[0], q[1], q[2]);
    };
    if (!geom::adjacent_ok(geom::face_normal(mesh, a), geom::face_normal(mesh, b), moved(a), moved(b))) return false;
  }
  return true;
}

bool is_tip(const TriMesh& mesh, VertexHandle v) { return geom::angle_deficit(mesh, v) > kTipDeficit; }

namespace {

/// CreaseGuard's part of a collapse (see plan_collapse in the header). 0: the creases do not
/// decide; 1: they do (h oriented so that its to-vertex is kept, `p` set, `in_place` when that end
/// stays); -1: refused.
int crease_collapse(const TriMesh& mesh, HalfedgeHandle& h, const CreaseGuard& creases, double target, Vec3& p,
                    bool& in_place) {
  if (creases.empty()) return 0;
  VertexHandle v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
  const Vec3 a = mesh.point(v0), b = mesh.point(v1);
  const CreaseLines::Kind k0 = creases.locate(a).kind, k1 = creases.locate(b).kind;
  using Kind = CreaseLines::Kind;
  if (k0 == Kind::None && k1 == Kind::None) return 0;
  const bool along = k0 != Kind::None && k1 != Kind::None && creases.along(mesh, mesh.edge_handle(h));
  if (k0 != Kind::None && k1 != Kind::None && !along) return -1;  // across: would join two creases
  if (along && k0 == Kind::Corner && k1 == Kind::Corner) return -1;
  // The end that stays: the one on a crease (not along), or the corner (along).
  const bool keep0 = along ? k0 == Kind::Corner : k0 != Kind::None;
  const bool keep1 = along ? k1 == Kind::Corner : k1 != Kind::None;
  if (keep0) h = mesh.opposite_halfedge_handle(h), std::swap(v0, v1);
  if (keep0 || keep1) {
    p = mesh.point(v1);
    in_place = true;
  } else {
    const Vec3 q = mesh.point(v0), r = mesh.point(v1);
    p = creases.onto(q + (r - q) * equalizing_parameter(q, r, collapse_neighbours(mesh, h), target), q, r);
    in_place = false;
  }
  return 1;
}

}  // namespace

bool plan_collapse(const TriMesh& mesh, EdgeHandle e, double target, double max_length, CollapsePlan& plan,
                   bool keep_tips, const CreaseGuard* creases) {
  HalfedgeHandle h = mesh.halfedge_handle(e, 0);
  VertexHandle v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
  if (!component_larger_than(mesh, v0, 4)) return false;
  if (creases && !creases->empty() && (mesh.is_boundary(v0) || mesh.is_boundary(v1))) {
    // Where a boundary and a crease meet, neither rule may move the other's vertex: a collapse
    // with a crease vertex at either end of an edge touching the boundary is not made.
    if (creases->on(mesh.point(v0)) || creases->on(mesh.point(v1))) return false;
  } else if (creases) {
    Vec3 p;
    bool in_place = false;
    const int decided = crease_collapse(mesh, h, *creases, target, p, in_place);
    if (decided < 0) return false;
    if (decided > 0) {
      if (!const_cast<TriMesh&>(mesh).is_collapse_ok(h)) return false;
      if (!collapse_geometry_ok(mesh, h, p, max_length)) return false;
      plan.halfedge = h;
      plan.position = p;
      plan.kept_in_place = in_place;
      return true;
    }
  }
  const bool b0 = mesh.is_boundary(v0), b1 = mesh.is_boundary(v1), along_boundary = mesh.is_boundary(e);
  if (along_boundary) {
    if (!boundary_loop_longer_than_3(mesh, h)) return false;
  } else if (b0 && b1) {
    return false;  // interior edge between two boundary vertices: would pinch
  } else if (b0) {
    h = mesh.opposite_halfedge_handle(h), std::swap(v0, v1);  // remove the interior end
  }
  // A tip stays when the other end is not one (an interior edge, neither end on the boundary).
  const bool interior = keep_tips && !(b0 || b1);
  const bool tip0 = interior && is_tip(mesh, v0), tip1 = interior && is_tip(mesh, v1);
  const bool keep_end = tip0 != tip1;
  if (tip0 && !tip1) h = mesh.opposite_halfedge_handle(h), std::swap(v0, v1);
  // The link condition before the position, which it does not depend on: on thin parts it fails
  // for a third of the cleanup's collapses (cheese's simplification: 191 000 of 508 000).
  // is_collapse_ok is not const in OpenMesh 9 but only reads (it uses status bits it resets).
  if (!const_cast<TriMesh&>(mesh).is_collapse_ok(h)) return false;
  Vec3 p;
  plan.kept_in_place = false;
  if (keep_end) {
    p = mesh.point(v1);  // the tip stays
    plan.kept_in_place = true;
  } else if (along_boundary || !(b0 || b1)) {
    // On the edge at the eq. 3.1 parameter (for a boundary edge, on the boundary curve).
    const Vec3 a = mesh.point(v0), b = mesh.point(v1);
    p = a + (b - a) * equalizing_parameter(a, b, collapse_neighbours(mesh, h), target);
  } else {
    p = mesh.point(v1);  // the boundary end stays
    plan.kept_in_place = true;
  }
  if (!collapse_geometry_ok(mesh, h, p, max_length)) return false;
  plan.halfedge = h;
  plan.position = p;
  return true;
}

VertexHandle apply_collapse(TriMesh& mesh, const CollapsePlan& plan) {
  const VertexHandle kept = mesh.to_vertex_handle(plan.halfedge);
  mesh.collapse(plan.halfedge);
  mesh.point(kept) = plan.position;
  return kept;
}

double collapse_length_limit(double m_i, double sigma) { return std::max(m_i + sigma, 2.0 * (m_i - sigma)); }

StellarCounts stellar_operations(TriMesh& mesh, const std::vector<unsigned>& list, double m_i, double sigma,
                                 const CreaseGuard* creases, std::vector<VertexHandle>* placed) {
  StellarCounts counts;
  std::vector<char> visited(mesh.n_vertices(), 0);
  auto visit_star = [&](VertexHandle v) {
    if (visited.size() < mesh.n_vertices()) visited.resize(mesh.n_vertices(), 0);
    visited[v.idx()] = 1;
    for (auto w : mesh.vv_range(v)) visited[w.idx()] = 1;
  };
  for (unsigned index : list) {
    const EdgeHandle e = mesh.edge_handle(index);
    if (mesh.status(e).deleted()) continue;
    const HalfedgeHandle h = mesh.halfedge_handle(e, 0);
    const VertexHandle v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
    if (visited[v0.idx()] && visited[v1.idx()]) continue;
    const double length = mesh.calc_edge_length(e);
    if (length > m_i + sigma) {
      const VertexHandle v = split_edge(mesh, e, m_i, creases);
      if (!v.is_valid()) continue;
      ++counts.splits;
      visit_star(v);
      if (placed) placed->push_back(v);
    } else if (length < m_i - sigma) {
      CollapsePlan plan;
      if (!plan_collapse(mesh, e, m_i, collapse_length_limit(m_i, sigma), plan, true, creases)) continue;
      const VertexHandle kept = apply_collapse(mesh, plan);
      visit_star(kept);
      ++counts.collapses;
      if (placed && !plan.kept_in_place) placed->push_back(kept);
    }
  }
  return counts;
}

}  // namespace remesh
