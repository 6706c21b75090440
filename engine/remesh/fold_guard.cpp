#include "remesh/fold_guard.h"

#include <algorithm>

#include "core/parallel.h"
#include "remesh/geometry.h"

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
  auto face_is_bad = [&](OpenMesh::FaceHandle f) {
    if (mesh.status(f).deleted()) return false;
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    const Vec3 &a0 = before[c[0].idx()], &b0 = before[c[1].idx()], &c0 = before[c[2].idx()];
    const Vec3 &a1 = mesh.point(c[0]), &b1 = mesh.point(c[1]), &c1 = mesh.point(c[2]);
    if (a0 == a1 && b0 == b1 && c0 == c1) return false;
    if (!geom::normals_agree(geom::cross_normal(a0, b0, c0), geom::cross_normal(a1, b1, c1), 0.0)) return true;
    const double floor_angle = std::min(geom::kMinAngle, geom::min_angle(a0, b0, c0));
    return geom::min_angle(a1, b1, c1) < floor_angle;
  };
  parallel_for(nf, threads, [&](std::size_t i) { bad[i] = face_is_bad(mesh.face_handle(static_cast<unsigned>(i))); });
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
        if (face_is_bad(f)) queue.push_back(f);
  }
  return restored;
}

}  // namespace remesh
