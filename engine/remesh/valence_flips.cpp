#include "remesh/valence_flips.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

using OpenMesh::EdgeHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::VertexHandle;

Quad quad_of(const TriMesh& mesh, EdgeHandle e) {
  const HalfedgeHandle h0 = mesh.halfedge_handle(e, 0), h1 = mesh.halfedge_handle(e, 1);
  return {mesh.from_vertex_handle(h0), mesh.to_vertex_handle(h0),
          mesh.to_vertex_handle(mesh.next_halfedge_handle(h0)), mesh.to_vertex_handle(mesh.next_halfedge_handle(h1))};
}

VertexInfo::VertexInfo(const TriMesh& mesh, unsigned threads)
    : valence(mesh.n_vertices()), boundary(mesh.n_vertices()) {
  parallel_for(mesh.n_vertices(), threads, [&](std::size_t i) {
    const auto v = mesh.vertex_handle(static_cast<unsigned>(i));
    if (mesh.status(v).deleted()) return;
    valence[i] = static_cast<int>(vertex_valence(mesh, v));
    boundary[i] = mesh.is_boundary(v);
  });
}

bool flip_is_safe(const TriMesh& mesh, EdgeHandle e, double f, const VertexInfo* info, bool turned_ok,
                  const CreaseGuard* creases) {
  if (mesh.status(e).deleted() || mesh.is_boundary(e) || !mesh.is_flip_ok(e)) return false;
  const Quad q = quad_of(mesh, e);
  if (creases && creases->along(mesh, e)) return false;
  // The ends lose an edge: keep interior valence >= 3 and boundary valence >= 2.
  for (VertexHandle v : {q.v0, q.v1}) {
    const bool boundary = info ? info->boundary[v.idx()] != 0 : mesh.is_boundary(v);
    const int valence = info ? info->valence[v.idx()] : static_cast<int>(vertex_valence(mesh, v));
    if (valence <= (boundary ? 2 : 3)) return false;
  }
  const Vec3 &p0 = mesh.point(q.v0), &p1 = mesh.point(q.v1), &p2 = mesh.point(q.v2), &p3 = mesh.point(q.v3);
  // Old faces (v0, v1, v2), (v1, v0, v3); new faces (v3, v1, v2), (v2, v0, v3).
  const Vec3 old_a = geom::cross_normal(p0, p1, p2), old_b = geom::cross_normal(p1, p0, p3);
  const Vec3 new_a = geom::cross_normal(p3, p1, p2), new_b = geom::cross_normal(p2, p0, p3);
  if (!turned_ok)
    for (const Vec3& n : {new_a, new_b})
      if (!geom::normals_agree(old_a, n) || !geom::normals_agree(old_b, n)) return false;
  if (!geom::adjacent_ok(old_a, old_b, new_a, new_b)) return false;
  // The four outer neighbours against the new face that takes over their shared edge.
  const HalfedgeHandle h0 = mesh.halfedge_handle(e, 0), h1 = mesh.halfedge_handle(e, 1);
  const std::pair<HalfedgeHandle, int> outer[4] = {{mesh.next_halfedge_handle(h0), 0},
                                                   {mesh.next_halfedge_handle(mesh.next_halfedge_handle(h1)), 1},
                                                   {mesh.next_halfedge_handle(mesh.next_halfedge_handle(h0)), 2},
                                                   {mesh.next_halfedge_handle(h1), 3}};
  for (const auto& [h, k] : outer) {
    const auto g = mesh.opposite_face_handle(h);
    if (!g.is_valid()) continue;
    const Vec3 ng = geom::face_normal(mesh, g);
    const Vec3& old_f = (k == 0 || k == 2) ? old_a : old_b;
    const Vec3& new_f = k < 2 ? new_a : new_b;
    if (!geom::adjacent_ok(old_f, ng, new_f, ng)) return false;
  }
  const double before = std::min(geom::min_angle(p0, p1, p2), geom::min_angle(p1, p0, p3));
  const double after = std::min(geom::min_angle(p3, p1, p2), geom::min_angle(p2, p0, p3));
  return after >= f * before && after >= std::min(geom::kMinAngle, before);
}

bool flip_improves(const TriMesh& mesh, EdgeHandle e, double f) {
  if (mesh.status(e).deleted() || mesh.is_boundary(e)) return false;
  return VertexInfo(mesh).improves(quad_of(mesh, e)) && flip_is_safe(mesh, e, f);
}

void SweepMarks::next_sweep() {
  for (auto v : was_touched_) previous_[v.idx()] = 0;
  if (first_) std::fill(previous_.begin(), previous_.end(), 0);
  first_ = false;
  for (auto v : touched_) previous_[v.idx()] = 1, current_[v.idx()] = 0;
  was_touched_.swap(touched_);
  touched_.clear();
}

void SweepMarks::offer_edges_around(const TriMesh& mesh, VertexHandle v, int after) {
  auto offer = [&](EdgeHandle e) {
    if (e.idx() > after) pending_[e.idx() / 64] |= std::uint64_t{1} << (e.idx() % 64);
  };
  for (auto h : mesh.voh_range(v)) {
    offer(mesh.edge_handle(h));
    if (!mesh.is_boundary(h)) offer(mesh.edge_handle(mesh.next_halfedge_handle(h)));
  }
}

namespace {

/// One sweep over the interior edges in index order; with `marks`, only those it says may have
/// changed.
std::size_t sweep(TriMesh& mesh, double f, VertexInfo& info, SweepMarks* marks, const CreaseGuard* creases) {
  std::size_t flips = 0;
  auto visit = [&](EdgeHandle e) {
    if (mesh.is_boundary(e)) return;
    const Quad q = quad_of(mesh, e);
    if (marks && !marks->any(q)) return;
    if (!info.improves(q) || !flip_is_safe(mesh, e, f, &info, false, creases)) return;
    mesh.flip(e);
    info.flipped(q);
    if (marks)
      for (auto v : {q.v0, q.v1, q.v2, q.v3}) marks->touch(v);
    ++flips;
  };
  if (marks) {
    marks->for_each_edge(mesh, visit);
  } else {
    for (auto e : mesh.edges()) visit(e);
  }
  return flips;
}

}  // namespace

std::size_t valence_flip_sweep(TriMesh& mesh, double f) {
  VertexInfo info(mesh);
  return sweep(mesh, f, info, nullptr, nullptr);
}

std::size_t valence_flips(TriMesh& mesh, double f, int max_sweeps, unsigned threads, const CreaseGuard* creases) {
  std::size_t total = 0;
  VertexInfo info(mesh, threads);
  SweepMarks marks(mesh.n_vertices());
  for (int s = 0; s < max_sweeps; ++s) {
    const std::size_t n = sweep(mesh, f, info, &marks, creases);
    total += n;
    if (n == 0) break;
    marks.next_sweep();
  }
  return total;
}

}  // namespace remesh
