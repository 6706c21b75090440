#include "remesh/reposition.h"

#include <algorithm>
#include <cmath>

namespace remesh {

double equalization_energy(const Vec3& a, const Vec3& b, double t, const std::vector<Vec3>& neighbours,
                           double target) {
  const Vec3 p = a + (b - a) * t;
  double e = 0;
  for (const Vec3& v : neighbours) {
    const double d = (p - v).norm() - target;
    e += d * d;
  }
  return e;
}

double equalizing_parameter(const Vec3& a, const Vec3& b, const std::vector<Vec3>& neighbours, double target) {
  if (neighbours.empty()) return 0.5;
  constexpr int kSamples = 16;
  int best = kSamples / 2;
  double best_e = equalization_energy(a, b, 0.5, neighbours, target);
  for (int i = 0; i <= kSamples; ++i) {
    if (i == kSamples / 2) continue;  // t = 0.5, measured above
    const double e = equalization_energy(a, b, double(i) / kSamples, neighbours, target);
    if (e < best_e) best_e = e, best = i;
  }
  double lo = std::max(0.0, double(best - 1) / kSamples), hi = std::min(1.0, double(best + 1) / kSamples);
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = equalization_energy(a, b, x1, neighbours, target);
  double f2 = equalization_energy(a, b, x2, neighbours, target);
  for (int it = 0; it < 40 && hi - lo > 1e-7; ++it) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = equalization_energy(a, b, x1, neighbours, target);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = equalization_energy(a, b, x2, neighbours, target);
    }
  }
  const double t = 0.5 * (lo + hi);
  // Keep the sampled optimum if the refinement did not beat it (flat or multimodal E).
  return equalization_energy(a, b, t, neighbours, target) <= best_e ? t : double(best) / kSamples;
}

std::vector<Vec3> split_neighbours(const TriMesh& mesh, OpenMesh::EdgeHandle e) {
  std::vector<Vec3> out;
  for (int s = 0; s < 2; ++s) {
    const auto h = mesh.halfedge_handle(e, s);
    out.push_back(mesh.point(mesh.to_vertex_handle(h)));
    if (!mesh.is_boundary(h)) out.push_back(mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))));
  }
  return out;
}

std::vector<Vec3> collapse_neighbours(const TriMesh& mesh, OpenMesh::HalfedgeHandle h) {
  const auto v0 = mesh.from_vertex_handle(h), v1 = mesh.to_vertex_handle(h);
  std::vector<OpenMesh::VertexHandle> ring;
  for (auto w : mesh.vv_range(v0))
    if (w != v1) ring.push_back(w);
  for (auto w : mesh.vv_range(v1))
    if (w != v0 && std::find(ring.begin(), ring.end(), w) == ring.end()) ring.push_back(w);
  std::vector<Vec3> out;
  out.reserve(ring.size());
  for (auto w : ring) out.push_back(mesh.point(w));
  return out;
}

}  // namespace remesh
