#include "remesh/projection.h"

#include <algorithm>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

Vec3 project_vertex(const TriMesh& mesh, OpenMesh::VertexHandle v, const Vec3& p, const Vec3& normal,
                    const ReferenceSurface& reference, NeighbourCache* cache) {
  if (mesh.is_boundary(v) && reference.has_boundary()) return reference.closest_boundary_point(p);
  return cache ? reference.closest_point(p, normal, *cache) : reference.closest_point(p, normal);
}

namespace {

/// The kd-tree answer a placed vertex's search starts from (project_vertices): its own, else the
/// first neighbour's that has one, else none. Any cache gives exact answers (reference_surface.h);
/// a neighbour's, one edge away, mostly answers without the kd-tree.
NeighbourCache seed_cache(const TriMesh& mesh, OpenMesh::VertexHandle v, const std::vector<NeighbourCache>* caches) {
  if (!caches) return {};
  auto filled = [&](OpenMesh::VertexHandle u) {
    return static_cast<std::size_t>(u.idx()) < caches->size() && (*caches)[u.idx()].surface != 0;
  };
  if (filled(v)) return (*caches)[v.idx()];
  for (auto w : mesh.vv_range(v))
    if (filled(w)) return (*caches)[w.idx()];
  return {};
}

}  // namespace

std::size_t project_vertices(TriMesh& mesh, const std::vector<OpenMesh::VertexHandle>& vertices,
                             const ReferenceSurface& reference, unsigned threads,
                             const std::vector<NeighbourCache>* caches) {
  auto live = [&](OpenMesh::VertexHandle v) { return !mesh.status(v).deleted() && !mesh.is_isolated(v); };
  std::vector<Vec3> target(vertices.size());
  parallel_for(
      vertices.size(), threads,
      [&](std::size_t k) {
        const auto v = vertices[k];
        if (!live(v)) return;
        NeighbourCache cache = seed_cache(mesh, v, caches);
        target[k] = project_vertex(mesh, v, mesh.point(v), geom::vertex_normal(mesh, v), reference, &cache);
      },
      /*block=*/64);
  std::size_t moved = 0;
  for (std::size_t k = 0; k < vertices.size(); ++k) {
    const auto v = vertices[k];
    if (!live(v) || target[k] == mesh.point(v) || !geom::move_is_safe(mesh, v, target[k])) continue;
    mesh.point(v) = target[k];
    ++moved;
  }
  return moved;
}

double project_onto_reference(TriMesh& mesh, const ReferenceSurface& reference, unsigned threads,
                              std::vector<NeighbourCache>* caches) {
  const std::size_t n = mesh.n_vertices();
  if (caches && caches->size() < n) caches->resize(n);
  const std::vector<Vec3> normals = geom::vertex_normals(mesh, threads);
  std::vector<Vec3> target(n);
  constexpr std::size_t kBlock = 512;
  std::vector<double> block_max(block_count(n, kBlock), 0.0);
  parallel_blocks(n, kBlock, threads, [&](std::size_t b, std::size_t e, std::size_t block) {
    double worst = 0;
    for (std::size_t i = b; i < e; ++i) {
      const auto v = mesh.vertex_handle(static_cast<unsigned>(i));
      const Vec3 p = mesh.point(v);
      if (mesh.status(v).deleted() || mesh.is_isolated(v)) {
        target[i] = p;
        continue;
      }
      target[i] = project_vertex(mesh, v, p, normals[i], reference, caches ? &(*caches)[i] : nullptr);
      worst = std::max(worst, (target[i] - p).norm());
    }
    block_max[block] = worst;
  });
  for (std::size_t i = 0; i < n; ++i) mesh.point(mesh.vertex_handle(static_cast<unsigned>(i))) = target[i];
  double worst = 0;
  for (double d : block_max) worst = std::max(worst, d);
  return worst;
}

}  // namespace remesh
