#include "test_helpers.h"

#include <algorithm>

#include "remesh/geometry.h"

namespace remesh::test {

double plain_mean_edge(const TriMesh& mesh) {
  double sum = 0;
  std::size_t n = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    sum += (mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h))).norm();
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

void scale_mean_edge(TriMesh& mesh, double mean) {
  const double f = mean / plain_mean_edge(mesh);
  for (auto v : mesh.vertices()) mesh.point(v) *= f;
}

double plain_inside_fraction(const TriMesh& mesh, double lo, double hi) {
  std::size_t in = 0, n = 0;
  for (auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    const double l = (mesh.point(mesh.to_vertex_handle(h)) - mesh.point(mesh.from_vertex_handle(h))).norm();
    in += (l >= lo && l <= hi) ? 1 : 0;
    ++n;
  }
  return n ? static_cast<double>(in) / static_cast<double>(n) : 1.0;
}

double brute_distance(const TriMesh& mesh, const Vec3& p) {
  double best = 1e300;
  for (auto f : mesh.faces()) {
    Vec3 q[3];
    int k = 0;
    for (auto v : mesh.fv_range(f)) q[k++] = mesh.point(v);
    best = std::min(best, (geom::closest_point_on_triangle(p, q[0], q[1], q[2]) - p).norm());
  }
  return best;
}

double box_edges_distance(const TriMesh& mesh, int n) {
  double worst = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (int a : {0, n})
      for (int b : {0, n})
        for (int k = 0; k <= 20 * n; ++k) {
          Vec3 p;
          p[axis] = k / 20.0, p[(axis + 1) % 3] = a, p[(axis + 2) % 3] = b;
          worst = std::max(worst, brute_distance(mesh, p));
        }
  return worst;
}

}  // namespace remesh::test
