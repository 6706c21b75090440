#include "remesh/fold_guard.h"

#include <algorithm>
#include <cstdint>

#include "core/parallel.h"
#include "remesh/geometry.h"
#include "remesh/projection.h"

namespace remesh {

std::vector<Vec3> snapshot_points(const TriMesh& mesh) {
  std::vector<Vec3> points(mesh.n_vertices());
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i] = mesh.point(mesh.vertex_handle(static_cast<unsigned>(i)));
  return points;
}

std::size_t undo_folds(TriMesh& mesh, const std::vector<Vec3>& before, unsigned threads) {
  const std::size_t nf = mesh.n_faces();
  std::vector<char> bad(nf, 0);
  auto normal_before = [&](OpenMesh::FaceHandle f) {
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    return geom::cross_normal(before[c[0].idx()], before[c[1].idx()], before[c[2].idx()]);
  };
  // Folded: turned by more than 90 degrees, or folded onto a neighbour (kMinAdjacentCos);
  // degenerate: a minimum angle below kMinAngle that it did not have before. The normals come from
  // `n_before(g)` and `n_now(g)`: tables in the first, parallel pass over every face (each normal
  // computed once, not once per neighbour), computed afresh after restores.
  auto face_is_bad = [&](OpenMesh::FaceHandle f, const auto& n_before, const auto& n_now) {
    if (mesh.status(f).deleted()) return false;
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    const Vec3 &a0 = before[c[0].idx()], &b0 = before[c[1].idx()], &c0 = before[c[2].idx()];
    const Vec3 &a1 = mesh.point(c[0]), &b1 = mesh.point(c[1]), &c1 = mesh.point(c[2]);
    if (a0 == a1 && b0 == b1 && c0 == c1) return false;
    const Vec3 n0 = n_before(f), n1 = n_now(f);
    if (!geom::normals_agree(n0, n1, 0.0)) return true;
    if (geom::AngleFloor([&] { return geom::min_angle(a0, b0, c0); }).breaks(a1, b1, c1)) return true;
    for (auto h : mesh.fh_range(f)) {
      const auto g = mesh.opposite_face_handle(h);
      if (!g.is_valid()) continue;
      if (!geom::adjacent_ok(n0, n_before(g), n1, n_now(g))) return true;
    }
    return false;
  };
  {
    std::vector<Vec3> was(nf);
    parallel_for(nf, threads, [&](std::size_t i) {
      const auto f = mesh.face_handle(static_cast<unsigned>(i));
      if (!mesh.status(f).deleted()) was[i] = normal_before(f);
    });
    const std::vector<Vec3> now = geom::face_normals(mesh, threads);
    auto table = [](const std::vector<Vec3>& t) { return [&t](OpenMesh::FaceHandle f) { return t[f.idx()]; }; };
    parallel_for(nf, threads, [&](std::size_t i) {
      bad[i] = face_is_bad(mesh.face_handle(static_cast<unsigned>(i)), table(was), table(now));
    });
  }
  auto fresh_now = [&](OpenMesh::FaceHandle f) { return geom::face_normal(mesh, f); };
  std::vector<OpenMesh::FaceHandle> queue;
  for (std::size_t i = 0; i < nf; ++i)
    if (bad[i]) queue.push_back(mesh.face_handle(static_cast<unsigned>(i)));
  std::size_t restored = 0;
  while (!queue.empty()) {
    std::vector<OpenMesh::VertexHandle> moved;
    for (auto f : queue) {
      OpenMesh::VertexHandle c[3];
      geom::face_vertices(mesh, f, c);
      for (auto v : c) {
        if (mesh.point(v) != before[v.idx()]) {
          mesh.point(v) = before[v.idx()];
          moved.push_back(v);
          ++restored;
        }
      }
    }
    queue.clear();
    for (auto v : moved)
      for (auto f : mesh.vf_range(v))
        if (face_is_bad(f, normal_before, fresh_now)) queue.push_back(f);
  }
  return restored;
}

std::size_t undo_interval_breaks(TriMesh& mesh, const std::vector<Vec3>& before, double e_min, double e_max,
                                 int halvings, const ReferenceSurface* reference, std::vector<NeighbourCache>* caches) {
  auto inside = [&](double length) { return length >= e_min && length <= e_max; };
  auto broken = [&](OpenMesh::EdgeHandle e) {
    const auto h = mesh.halfedge_handle(e, 0);
    const auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h);
    return !inside((mesh.point(a) - mesh.point(b)).norm()) && inside((before[a.idx()] - before[b.idx()]).norm());
  };
  std::vector<OpenMesh::EdgeHandle> queue;
  for (auto e : mesh.edges())
    if (!mesh.status(e).deleted() && broken(e)) queue.push_back(e);
  std::vector<std::uint8_t> retreats(mesh.n_vertices(), 0);
  std::size_t moves = 0;
  auto move_back = [&](const std::vector<OpenMesh::EdgeHandle>& edges) {
    std::vector<OpenMesh::VertexHandle> moved;
    for (auto e : edges) {
      if (!broken(e)) continue;  // mended by a move back of a neighbour in this round
      const auto h = mesh.halfedge_handle(e, 0);
      for (auto v : {mesh.from_vertex_handle(h), mesh.to_vertex_handle(h)}) {
        const Vec3& was = before[v.idx()];
        if (mesh.point(v) == was) continue;
        mesh.point(v) = retreats[v.idx()]++ < halvings ? (mesh.point(v) + was) * 0.5 : was;
        moved.push_back(v);
        ++moves;
      }
    }
    return moved;
  };
  std::vector<OpenMesh::VertexHandle> halved;  // every vertex moved, once each
  std::vector<char> listed(reference ? mesh.n_vertices() : 0, 0);
  while (!queue.empty()) {
    const std::vector<OpenMesh::VertexHandle> moved = move_back(queue);
    queue.clear();
    for (auto v : moved) {
      if (reference && !listed[v.idx()]) listed[v.idx()] = 1, halved.push_back(v);
      for (auto e : mesh.ve_range(v))
        if (broken(e)) queue.push_back(e);
    }
  }
  if (!reference) return moves;
  // The vertices left half way are projected, once each at the end (a projection per step took
  // cheese's refinement 0.25 s more); what that takes out of the interval goes back all the way.
  for (auto v : halved) {
    const Vec3& was = before[v.idx()];
    if (mesh.point(v) == was) continue;
    NeighbourCache* cache = caches && static_cast<std::size_t>(v.idx()) < caches->size() ? &(*caches)[v.idx()] : nullptr;
    mesh.point(v) = project_vertex(mesh, v, mesh.point(v), geom::vertex_normal(mesh, v), *reference, cache);
    retreats[v.idx()] = static_cast<std::uint8_t>(halvings);  // a next move goes all the way
    for (auto e : mesh.ve_range(v))
      if (broken(e)) queue.push_back(e);
  }
  while (!queue.empty()) {
    const std::vector<OpenMesh::VertexHandle> moved = move_back(queue);
    queue.clear();
    for (auto v : moved)
      for (auto e : mesh.ve_range(v))
        if (broken(e)) queue.push_back(e);
  }
  return moves;
}

}  // namespace remesh
