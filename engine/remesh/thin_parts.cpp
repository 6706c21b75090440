#include "remesh/thin_parts.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

namespace {

/// Is the reference thinner than `limit` at edge e (see thin_parts.h)? False for an edge whose
/// faces' normals cancel or are degenerate.
bool in_thin_part(const TriMesh& mesh, const ReferenceSurface& reference, OpenMesh::EdgeHandle e, double limit) {
  const auto h = mesh.halfedge_handle(e, 0);
  Vec3 normal(0, 0, 0);
  for (auto g : {h, mesh.opposite_halfedge_handle(h)})
    if (!mesh.is_boundary(g)) {
      const Vec3 n = geom::face_normal(mesh, mesh.face_handle(g));
      if (const double l = n.norm(); l > 0) normal += n / l;
    }
  if (!(normal.norm() > 0)) return false;
  const Vec3 mid = 0.5 * (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h)));
  return reference.opposite_side_within(mid, normal.normalized(), limit);
}

}  // namespace

double thickness_at(const TriMesh& mesh, const ReferenceSurface& reference, OpenMesh::VertexHandle v, double limit) {
  const Vec3 n = geom::vertex_normal(mesh, v);
  if (!(n.norm() > 0)) return std::numeric_limits<double>::infinity();
  return reference.opposite_side_distance(mesh.point(v), n.normalized(), limit);
}

bool thinner_than(const TriMesh& mesh, const ReferenceSurface& reference, OpenMesh::VertexHandle v, double limit) {
  const Vec3 n = geom::vertex_normal(mesh, v);
  return n.norm() > 0 && reference.opposite_side_within(mesh.point(v), n.normalized(), limit);
}

ThinParts thin_parts(const TriMesh& mesh, const ReferenceSurface& reference, double e_min, double e_max,
                     unsigned threads, const CreaseGuard* creases) {
  ThinParts out;
  out.limit = 2.0 * e_min / std::sqrt(3.0);
  std::vector<OpenMesh::EdgeHandle> outside;
  for (auto e : mesh.edges()) {
    if (mesh.status(e).deleted()) continue;
    const double l = mesh.calc_edge_length(e);
    if (l < e_min || l > e_max) outside.push_back(e);
  }
  out.outside = outside.size();
  auto irregular = [&](OpenMesh::VertexHandle v) { return mesh.valence(v) != geom::target_valence(mesh, v); };
  for (auto e : outside) {
    const auto h = mesh.halfedge_handle(e, 0);
    if (irregular(mesh.from_vertex_handle(h)) || irregular(mesh.to_vertex_handle(h))) ++out.at_irregular;
    if (creases && (creases->on(mesh.point(mesh.from_vertex_handle(h))) || creases->on(mesh.point(mesh.to_vertex_handle(h)))))
      ++out.at_creases;
  }
  std::atomic<std::size_t> thin{0};
  parallel_for(outside.size(), threads, [&](std::size_t i) {
    if (in_thin_part(mesh, reference, outside[i], out.limit)) ++thin;
  }, 64);
  out.in_thin_parts = thin;

  out.vertex_limit = 2.0 * e_max;
  std::vector<OpenMesh::VertexHandle> sample;
  const std::size_t stride =
      std::max<std::size_t>(1, (mesh.n_vertices() + kThicknessSample - 1) / kThicknessSample);
  out.sampled = stride > 1;
  // Every vertex whose index hashes to 0 modulo the stride: every k-th by index would follow the
  // order the splits numbered the vertices in (cow: 90.5 % regular where thick against 89.4 % over
  // all of them).
  auto picked = [&](std::size_t i) {
    std::uint64_t x = i + 0x9E3779B97F4A7C15ull;  // splitmix64
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return (x ^ (x >> 31)) % stride == 0;
  };
  for (auto v : mesh.vertices())
    if (picked(static_cast<std::size_t>(v.idx())) && !mesh.is_boundary(v) && !mesh.is_isolated(v))
      sample.push_back(v);
  std::vector<char> thinner(sample.size(), 0);
  parallel_for(sample.size(), threads, [&](std::size_t i) {
    thinner[i] = thinner_than(mesh, reference, sample[i], out.vertex_limit);
  }, 64);
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const bool regular = mesh.valence(sample[i]) == 6;
    if (thinner[i]) ++out.vertices_thinner, out.regular_thinner += regular;
    else ++out.vertices_thicker, out.regular_thicker += regular;
  }
  return out;
}

}  // namespace remesh
