#include "remesh/surface_distance.h"

#include <algorithm>

#include "core/parallel.h"
#include "remesh/preconditions.h"

namespace remesh {

std::vector<Vec3> distance_samples(const TriMesh& mesh) {
  std::vector<Vec3> points;
  points.reserve(mesh.n_vertices() + mesh.n_edges() + mesh.n_faces());
  for (auto v : mesh.vertices())
    if (!mesh.status(v).deleted()) points.push_back(mesh.point(v));
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted()) continue;
    const auto h = mesh.halfedge_handle(e, 0);
    points.push_back(0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h))));
  }
  for (auto f : mesh.faces()) {
    if (mesh.status(f).deleted()) continue;
    Vec3 sum(0, 0, 0);
    int n = 0;
    for (auto v : mesh.fv_range(f)) sum += mesh.point(v), ++n;
    if (n > 0) points.push_back(sum / n);
  }
  return points;
}

double largest_distance(const std::vector<Vec3>& points, const TriangleBvh& to, unsigned threads) {
  constexpr std::size_t kBlock = 1024;
  std::vector<double> block_max(block_count(points.size(), kBlock), 0.0);
  parallel_blocks(points.size(), kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    double worst = 0;
    for (std::size_t i = b; i < e; ++i) worst = std::max(worst, to.distance(points[i]));
    block_max[block] = worst;
  });
  return block_max.empty() ? 0.0 : *std::max_element(block_max.begin(), block_max.end());
}

SurfaceDistance surface_distance(const TriMesh& result, const TriMesh& input, unsigned threads) {
  SurfaceDistance d;
  d.result_to_input = largest_distance(distance_samples(result), TriangleBvh(input), threads);
  d.input_to_result = largest_distance(distance_samples(input), TriangleBvh(result), threads);
  d.diagonal = bounding_box_diagonal(input);
  // A midpoint or centroid lies on its own face within rounding (1e-16 of the size): that is 0.
  const double noise = 1e-12 * d.diagonal;
  for (double* side : {&d.result_to_input, &d.input_to_result})
    if (*side <= noise) *side = 0;
  return d;
}

}  // namespace remesh
