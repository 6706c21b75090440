#include "remesh/low_pass_filter.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/parallel.h"
#include "remesh/geometry.h"

namespace remesh {

namespace {

/// Per-thread "seen" stamps for the ring walk: a vertex is seen in the current walk when its stamp
/// equals the walk's number. No clearing between walks, no std::set.
struct RingScratch {
  std::vector<std::uint32_t> stamp;
  std::uint32_t walk = 0;
  std::vector<OpenMesh::VertexHandle> frontier, next;

  void begin(std::size_t n_vertices) {
    if (stamp.size() < n_vertices) stamp.resize(n_vertices, 0);
    if (++walk == 0) {  // wrapped: clear once every 4 billion walks
      std::fill(stamp.begin(), stamp.end(), 0);
      walk = 1;
    }
  }
};

thread_local RingScratch scratch;

/// The ring-weighted centroid of the k rings around v, or v itself if it has no neighbours.
Vec3 ring_centroid(const TriMesh& mesh, OpenMesh::VertexHandle v, int rings) {
  RingScratch& s = scratch;
  s.begin(mesh.n_vertices());
  s.stamp[v.idx()] = s.walk;
  s.frontier.assign(1, v);
  Vec3 sum(0, 0, 0);
  double weight = 0;
  for (int r = 1; r <= rings && !s.frontier.empty(); ++r) {
    s.next.clear();
    for (auto u : s.frontier) {
      for (auto w : mesh.vv_range(u)) {
        if (s.stamp[w.idx()] == s.walk) continue;
        s.stamp[w.idx()] = s.walk;
        s.next.push_back(w);
      }
    }
    const double wr = 1.0 / r;
    for (auto w : s.next) sum += mesh.point(w) * wr;
    weight += wr * static_cast<double>(s.next.size());
    std::swap(s.frontier, s.next);
  }
  return weight > 0 ? sum / weight : mesh.point(v);
}

}  // namespace

bool is_corner(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  return std::abs(geom::angle_deficit(mesh, v)) > kCornerDeficit;
}

std::vector<Vec3> low_pass_displacements(const TriMesh& mesh, int rings, unsigned threads,
                                         const CreaseLines* creases, double tol) {
  const std::vector<Vec3> normals = geom::vertex_normals(mesh, threads);
  std::vector<Vec3> moves(mesh.n_vertices(), Vec3(0, 0, 0));
  parallel_for(mesh.n_vertices(), threads, [&](std::size_t i) {
    const auto v = mesh.vertex_handle(static_cast<unsigned>(i));
    if (mesh.status(v).deleted() || mesh.is_boundary(v)) return;  // isolated counts as boundary
    if (is_corner(mesh, v)) return;
    Vec3 t = ring_centroid(mesh, v, rings) - mesh.point(v);
    if (creases && !creases->empty()) {
      const CreaseLines::Where where = creases->locate(mesh.point(v), tol);
      if (where.kind == CreaseLines::Kind::Corner) return;
      if (where.kind == CreaseLines::Kind::Line) {
        moves[i] = CreaseLines::slide(mesh.point(v), where, t);
        return;
      }
    }
    const Vec3& n = normals[i];
    t -= n * (t | n);
    moves[i] = t;
  }, 256);
  return moves;
}

double low_pass_filter(TriMesh& mesh, int rings, unsigned threads, const CreaseLines* creases, double tol) {
  const std::vector<Vec3> moves = low_pass_displacements(mesh, rings, threads, creases, tol);
  double worst = 0;
  for (std::size_t i = 0; i < moves.size(); ++i) {
    mesh.point(mesh.vertex_handle(static_cast<unsigned>(i))) += moves[i];
    worst = std::max(worst, moves[i].norm());
  }
  return worst;
}

}  // namespace remesh
