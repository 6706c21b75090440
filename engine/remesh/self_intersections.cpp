#include "remesh/self_intersections.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <vector>

#include "core/parallel.h"
#include "remesh/geometry.h"
#include "remesh/point_index.h"

namespace remesh {

namespace {

/// Six times the signed volume of (a, b, c, d): positive when d lies on the side of (a, b, c)
/// its normal points to.
double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return ((b - a) % (c - a)) | (d - a);
}

/// Does segment pq pass through the inside of triangle abc (strictly: touching does not count)?
bool segment_crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
  if (!((sp > 0 && sq < 0) || (sp < 0 && sq > 0))) return false;
  const double u = orient(p, q, a, b), v = orient(p, q, b, c), w = orient(p, q, c, a);
  return (u > 0 && v > 0 && w > 0) || (u < 0 && v < 0 && w < 0);
}

}  // namespace

FaceSpheres face_spheres(const TriMesh& mesh) {
  FaceSpheres s;
  s.centres.resize(mesh.n_faces());
  s.radii.resize(mesh.n_faces());
  s.corners.resize(mesh.n_faces());
  for (auto f : mesh.faces()) {
    OpenMesh::VertexHandle c[3];
    geom::face_vertices(mesh, f, c);
    for (int k = 0; k < 3; ++k) s.corners[f.idx()][k] = c[k].idx();
    const Vec3 &a = mesh.point(c[0]), &b = mesh.point(c[1]), &d = mesh.point(c[2]);
    const Vec3 centre = (a + b + d) / 3.0;
    const double r = std::sqrt(std::max({(a - centre).sqrnorm(), (b - centre).sqrnorm(), (d - centre).sqrnorm()}));
    s.centres[f.idx()] = centre;
    s.radii[f.idx()] = r;
    s.largest = std::max(s.largest, r);
  }
  return s;
}

namespace {

/// faces_cross for faces with corners x and y (vertex indices).
bool corners_cross(const TriMesh& mesh, const std::array<int, 3>& x, const std::array<int, 3>& y) {
  int shared = 0;
  for (int u : x)
    for (int w : y) shared += u == w;
  if (shared >= 2) return false;
  auto point = [&](int i) -> const Vec3& { return mesh.point(OpenMesh::VertexHandle(i)); };
  return triangles_cross(point(x[0]), point(x[1]), point(x[2]), point(y[0]), point(y[1]), point(y[2]));
}

std::array<int, 3> corners_of(const TriMesh& mesh, OpenMesh::FaceHandle f) {
  OpenMesh::VertexHandle c[3];
  geom::face_vertices(mesh, f, c);
  return {c[0].idx(), c[1].idx(), c[2].idx()};
}

}  // namespace

bool faces_cross(const TriMesh& mesh, OpenMesh::FaceHandle f, OpenMesh::FaceHandle g) {
  return corners_cross(mesh, corners_of(mesh, f), corners_of(mesh, g));
}

bool triangles_cross(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& e, const Vec3& f) {
  const Vec3 t[3] = {a, b, c}, u[3] = {d, e, f};
  int shared_t = -1, shared_u = -1, shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (t[i] == u[j]) shared_t = i, shared_u = j, ++shared;
  if (shared >= 2) return false;
  if (shared == 1) {
    // Both planes hold the line through the common corner s along which they meet; the part both
    // triangles hold, if any, starts at s and ends where it leaves one of them, through the edge
    // opposite s.
    const Vec3 &p = t[(shared_t + 1) % 3], &q = t[(shared_t + 2) % 3];
    const Vec3 &r = u[(shared_u + 1) % 3], &s = u[(shared_u + 2) % 3];
    return segment_crosses(p, q, d, e, f) || segment_crosses(r, s, a, b, c);
  }
  // Two triangles in general position meet along a segment whose ends lie on edges of them.
  for (int i = 0; i < 3; ++i) {
    if (segment_crosses(t[i], t[(i + 1) % 3], d, e, f)) return true;
    if (segment_crosses(u[i], u[(i + 1) % 3], a, b, c)) return true;
  }
  return false;
}

bool sphere_meets(const Box& box, const Vec3& centre, double radius, double grow) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double below = box.lo[k] - grow - centre[k], above = centre[k] - box.hi[k] - grow;
    const double d = std::max({below, above, 0.0});
    d2 += d * d;
  }
  // With a margin: for a sphere through a corner of the box, rounding can put the corner just
  // outside the sphere computed from it.
  const double reach = radius * (1 + 1e-9) + 1e-300;
  return d2 <= reach * reach;
}

std::vector<std::pair<unsigned, unsigned>> find_self_intersections(const TriMesh& mesh, unsigned threads,
                                                                   const Box* region) {
  const FaceSpheres spheres = face_spheres(mesh);
  // The faces looked at: all, or those within reach of the region (the faces meeting it, and every
  // face that can cross one of them: its sphere meets theirs, so it meets the region grown by
  // their largest diameter).
  std::vector<unsigned> faces;
  std::vector<char> in_region;
  if (region) {
    in_region.assign(mesh.n_faces(), 0);
    double largest = 0;
    for (std::size_t i = 0; i < mesh.n_faces(); ++i)
      if (sphere_meets(*region, spheres.centres[i], spheres.radii[i]))
        in_region[i] = 1, largest = std::max(largest, spheres.radii[i]);
    for (std::size_t i = 0; i < mesh.n_faces(); ++i)
      if (in_region[i] || sphere_meets(*region, spheres.centres[i], spheres.radii[i], 2 * largest))
        faces.push_back(static_cast<unsigned>(i));
  } else {
    faces.resize(mesh.n_faces());
    std::iota(faces.begin(), faces.end(), 0u);
  }
  std::vector<Vec3> centres(faces.size());
  for (std::size_t k = 0; k < faces.size(); ++k) centres[k] = spheres.centres[faces[k]];
  const PointIndex index(std::move(centres));
  const std::size_t n = faces.size();
  constexpr std::size_t kBlock = 1024;
  std::vector<std::vector<std::pair<unsigned, unsigned>>> found(block_count(n, kBlock));
  parallel_blocks(n, kBlock, threads, [&](std::size_t begin, std::size_t end, std::size_t block) {
    std::vector<std::uint32_t> near;
    for (std::size_t k = begin; k < end; ++k) {
      // A pair whose spheres overlap is found from the face with the larger sphere (the lower
      // index on a tie), whose centre lies within twice its radius of the other's.
      const unsigned i = faces[k];
      const double ri = spheres.radii[i];
      index.within(spheres.centres[i], 2 * ri * (1 + 1e-9), near);
      for (std::uint32_t l : near) {
        const unsigned j = faces[l];
        const double rj = spheres.radii[j];
        if (j == i || rj > ri || (rj == ri && j < i)) continue;
        if (region && !in_region[i] && !in_region[j]) continue;
        const double r = ri + rj;
        if ((spheres.centres[i] - spheres.centres[j]).sqrnorm() > r * r) continue;
        if (corners_cross(mesh, spheres.corners[i], spheres.corners[j]))
          found[block].emplace_back(std::min(i, j), std::max(i, j));
      }
    }
  });
  std::vector<std::pair<unsigned, unsigned>> pairs;
  for (auto& b : found) pairs.insert(pairs.end(), b.begin(), b.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace remesh
