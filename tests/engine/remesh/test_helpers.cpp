#include "test_helpers.h"

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

}  // namespace remesh::test
